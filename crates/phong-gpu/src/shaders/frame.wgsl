// What both GPU paths share: the frame's bindings, and the vertex and fragment stages as
// functions (the pipeline's entry points in render.wgsl, the compute rasterizer's in raster.wgsl).

struct Frame {
    clip_from_world: mat4x4<f32>,
    // xyz: camera position; w: near.
    eye: vec4<f32>,
    // xyz: unit view direction; w: far.
    forward: vec4<f32>,
    // xyz: global ambient light; w: unused.
    ambient: vec4<f32>,
    // x: number of lights.
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> objects: array<ObjectParams>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
    @location(3) @interpolate(flat) flat_color: vec3<f32>,
    @location(4) @interpolate(flat) object: u32,
    // Two-sided lighting, as OpenGL: colours lit with the flipped normal, for back faces.
    @location(5) color_back: vec3<f32>,
    @location(6) @interpolate(flat) flat_back: vec3<f32>,
    // Textured objects (render.wgsl): texture coordinates, and Gouraud's and flat shading's
    // specular colours, added after the texture (front, back).
    @location(7) uv: vec4<f32>,
    @location(8) spec: vec3<f32>,
    @location(9) spec_back: vec3<f32>,
    @location(10) @interpolate(flat) flat_spec: vec3<f32>,
    @location(11) @interpolate(flat) flat_spec_back: vec3<f32>,
    // The vertex colour (white where the mesh has none).
    @location(12) vcolor: vec3<f32>,
    // The tangent (w: the bitangent's sign), for normal maps.
    @location(13) tangent: vec4<f32>,
}

// The object's options with the per-point two-sided flip off: the renderer flips by polygon
// facing instead, as OpenGL.
fn raster_options(o: ObjectParams) -> Options {
    var opt = o.options;
    opt.flags.z = 0u;
    return opt;
}

// The vertex stage: clip position, and the colours of Gouraud and flat shading (front and,
// for two-sided objects, back). `centroid`: flat shading's lighting point.
fn vertex(position: vec3<f32>, normal: vec3<f32>, centroid: vec3<f32>, object: u32) -> VsOut {
    let o = objects[object];
    let c = frame.clip_from_world * vec4<f32>(position, 1.0);
    var out: VsOut;
    // OpenGL's clip depth (−w..w) to WebGPU's (0..w): window depth z/w·0.5 + 0.5 as on the CPU.
    out.clip = vec4<f32>(c.x, c.y, (c.z + c.w) * 0.5, c.w);
    out.world = position;
    out.normal = normal;
    out.object = object;
    out.color = vec3<f32>(0.0);
    out.flat_color = vec3<f32>(0.0);
    out.color_back = vec3<f32>(0.0);
    out.flat_back = vec3<f32>(0.0);
    let interpolation = o.options.mode.x;
    let output = o.options.mode.y;
    let two_sided = o.options.flags.z != 0u;
    let opt = raster_options(o);
    let amb = frame.ambient.xyz;
    let nl = frame.counts.x;
    if (interpolation == 1u && output < 4u) {
        out.color = term(output, shade(position, normal, o.material, opt, amb, nl));
        if (two_sided) {
            out.color_back = term(output, shade(position, -normal, o.material, opt, amb, nl));
        }
    } else if (interpolation == 0u && output < 4u) {
        out.flat_color = term(output, shade(centroid, normal, o.material, opt, amb, nl));
        if (two_sided) {
            out.flat_back = term(output, shade(centroid, -normal, o.material, opt, amb, nl));
        }
    }
    return out;
}

// The fragment stage: the colour of a point with interpolated `f`; `back`: a back face
// (two-sided objects only; normals flipped).
fn fragment(f: VsOut, back: bool) -> vec3<f32> {
    let o = objects[f.object];
    var normal = f.normal;
    if (back) {
        normal = -normal;
    }
    let interpolation = o.options.mode.x;
    let output = o.options.mode.y;
    var c: vec3<f32>;
    if (output == 4u) {
        let n = normalize_or_zero(normal);
        if (all(n == vec3<f32>(0.0))) {
            c = vec3<f32>(0.0);
        } else {
            c = n * 0.5 + 0.5;
        }
    } else if (output == 5u) {
        let d = dot(f.world - frame.eye.xyz, frame.forward.xyz);
        let near = frame.eye.w;
        let far = frame.forward.w;
        c = vec3<f32>(clamp(1.0 - (d - near) / (far - near), 0.0, 1.0));
    } else if (interpolation == 0u) {
        c = select(f.flat_color, f.flat_back, back);
    } else if (interpolation == 1u) {
        c = select(f.color, f.color_back, back);
    } else {
        c = term(output, shade(f.world, normal, o.material, raster_options(o), frame.ambient.xyz, frame.counts.x));
    }
    return c;
}
