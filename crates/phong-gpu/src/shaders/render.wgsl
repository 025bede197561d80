// The render pipeline's entry points: the scene's triangles with per-object shading settings
// (object = instance index), drawn by the GPU's rasterizer; textured objects sampled here with
// their group 1 (the CPU's equation: phong-core's `shade_textured` and `Lit::modulate`).

struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // Flat shading: the triangle's centroid (its normal is then the facet normal).
    @location(2) centroid: vec3<f32>,
    // Texture coordinates: the mesh's first set in xy, its second in zw.
    @location(3) uv: vec4<f32>,
    @location(4) color: vec3<f32>,
    @location(5) tangent: vec4<f32>,
}

// An object's texture maps (textures.rs); a white 1×1 texture where a map is absent.
struct Maps {
    // Diffuse, ambient, specular, emission maps set.
    present: vec4<u32>,
    // Shininess and alpha maps set; their channels (0 r, 1 g, 2 b, 3 a, 4 luminance).
    scalar: vec4<u32>,
    // x: alpha cutoff; y: 1 with an alpha test; z: 1 when textured; w: the material's alpha.
    cutoff: vec4<f32>,
    // x: 1 for a blended object; y: 1 where vertex colours tint the diffuse texel.
    blend: vec4<f32>,
    // A normal map: x 1 where there is one, y its scale, z 1 for green along −v.
    normal: vec4<f32>,
    // A metallic-roughness map: x 1 where there is one, y metallic, z roughness; w 1 with an
    // occlusion map.
    pbr: vec4<f32>,
    // The base colour factor; w the occlusion's strength.
    base: vec4<f32>,
    // Per map: the transform's linear part by columns, then its offset (xy) and the set of
    // coordinates it reads (z: 0 or 1).
    transforms: array<vec4<f32>, 18>,
}

@group(1) @binding(0) var<uniform> maps: Maps;
@group(1) @binding(1) var t_diffuse: texture_2d<f32>;
@group(1) @binding(2) var t_ambient: texture_2d<f32>;
@group(1) @binding(3) var t_specular: texture_2d<f32>;
@group(1) @binding(4) var t_emission: texture_2d<f32>;
@group(1) @binding(5) var t_shininess: texture_2d<f32>;
@group(1) @binding(6) var t_alpha: texture_2d<f32>;
@group(1) @binding(7) var t_normal: texture_2d<f32>;
@group(1) @binding(8) var t_metal_rough: texture_2d<f32>;
@group(1) @binding(9) var t_occlusion: texture_2d<f32>;
@group(1) @binding(10) var s_diffuse: sampler;
@group(1) @binding(11) var s_ambient: sampler;
@group(1) @binding(12) var s_specular: sampler;
@group(1) @binding(13) var s_emission: sampler;
@group(1) @binding(14) var s_shininess: sampler;
@group(1) @binding(15) var s_alpha: sampler;
@group(1) @binding(16) var s_normal: sampler;
@group(1) @binding(17) var s_metal_rough: sampler;
@group(1) @binding(18) var s_occlusion: sampler;

// A textured object's light before its texels: (primary, specular), as phong-core's `Lit` with
// every term in the primary colour (Gouraud and flat shading), or the term an output shows.
fn lit(position: vec3<f32>, normal: vec3<f32>, object: u32) -> array<vec3<f32>, 2> {
    let o = objects[object];
    let s = shade(position, normal, o.material, raster_options(o), frame.ambient.xyz, frame.counts.x);
    let zero = vec3<f32>(0.0);
    switch o.options.mode.y {
        case 1u: { return array<vec3<f32>, 2>(s.ambient, zero); }
        case 2u: { return array<vec3<f32>, 2>(s.diffuse, zero); }
        case 3u: { return array<vec3<f32>, 2>(zero, s.specular); }
        default: {
            var p = s.ambient + s.diffuse;
            var q = s.specular;
            if (o.options.flags.y != 0u) {
                p = clamp(p, zero, vec3<f32>(1.0));
                q = clamp(q, zero, vec3<f32>(1.0));
            }
            return array<vec3<f32>, 2>(p, q);
        }
    }
}

@vertex
fn vs_main(v: VsIn, @builtin(instance_index) object: u32) -> VsOut {
    var out = vertex(v.position, v.normal, v.centroid, object);
    out.uv = v.uv;
    out.vcolor = v.color;
    out.tangent = v.tangent;
    let o = objects[object];
    let interpolation = o.options.mode.x;
    let two_sided = o.options.flags.z != 0u;
    if (maps.cutoff.z != 0.0 && o.options.mode.y < 4u && interpolation < 2u) {
        var p = v.position;
        if (interpolation == 0u) {
            p = v.centroid;
        }
        let front = lit(p, v.normal, object);
        var back = front;
        if (two_sided) {
            back = lit(p, -v.normal, object);
        }
        if (interpolation == 1u) {
            out.color = front[0];
            out.spec = front[1];
            out.color_back = back[0];
            out.spec_back = back[1];
        } else {
            out.flat_color = front[0];
            out.flat_spec = front[1];
            out.flat_back = back[0];
            out.flat_spec_back = back[1];
        }
    }
    return out;
}

// Map `k`'s coordinates from the mesh's two sets `uvs` (its set's, transformed), and its
// derivatives from theirs.
fn map_uv(k: u32, uvs: vec4<f32>) -> vec2<f32> {
    let a = maps.transforms[2u * k];
    let o = maps.transforms[2u * k + 1u];
    let uv = select(uvs.xy, uvs.zw, o.z != 0.0);
    return vec2<f32>(a.x * uv.x + a.z * uv.y + o.x, a.y * uv.x + a.w * uv.y + o.y);
}

fn map_d(k: u32, ds: vec4<f32>) -> vec2<f32> {
    let a = maps.transforms[2u * k];
    let d = select(ds.xy, ds.zw, maps.transforms[2u * k + 1u].z != 0.0);
    return vec2<f32>(a.x * d.x + a.z * d.y, a.y * d.x + a.w * d.y);
}

fn channel(c: u32, t: vec4<f32>) -> f32 {
    switch c {
        case 0u: { return t.x; }
        case 1u: { return t.y; }
        case 2u: { return t.z; }
        case 3u: { return t.w; }
        default: { return 0.2126 * t.x + 0.7152 * t.y + 0.0722 * t.z; }
    }
}

struct Texels {
    diffuse: vec4<f32>,
    ambient: vec3<f32>,
    specular: vec3<f32>,
    emission: vec3<f32>,
    shininess: f32,
    alpha: f32,
    // The normal map's tangent-space normal (z 1 without one).
    normal: vec3<f32>,
    // The occlusion on the ambient terms (1 without a map).
    occlusion: f32,
}

// phong-core's `MetalRough::MAX_SHININESS` (a test in lib.rs holds them equal).
const MAX_SHININESS: f32 = 10000.0;

// phong-core's `MetalRough::shininess`.
fn roughness_shininess(roughness: f32) -> f32 {
    let r = clamp(roughness, 0.0, 1.0);
    let a = r * r;
    if (a > 0.0) {
        return clamp(2.0 / (a * a) - 2.0, 0.0, MAX_SHININESS);
    }
    return MAX_SHININESS;
}

// Every map sampled at its set of `uv` with the screen derivatives `dx`, `dy` (both sets,
// as `uv`; 1 where a map is absent).
fn texels(uv: vec4<f32>, dx: vec4<f32>, dy: vec4<f32>) -> Texels {
    var t: Texels;
    t.diffuse = vec4<f32>(1.0);
    t.ambient = vec3<f32>(1.0);
    t.specular = vec3<f32>(1.0);
    t.emission = vec3<f32>(1.0);
    t.shininess = 1.0;
    t.alpha = 1.0;
    t.normal = vec3<f32>(0.0, 0.0, 1.0);
    t.occlusion = 1.0;
    if (maps.present.x != 0u) {
        t.diffuse = textureSampleGrad(t_diffuse, s_diffuse, map_uv(0u, uv), map_d(0u, dx), map_d(0u, dy));
    }
    if (maps.present.y != 0u) {
        t.ambient = textureSampleGrad(t_ambient, s_ambient, map_uv(1u, uv), map_d(1u, dx), map_d(1u, dy)).xyz;
    }
    if (maps.present.z != 0u) {
        t.specular = textureSampleGrad(t_specular, s_specular, map_uv(2u, uv), map_d(2u, dx), map_d(2u, dy)).xyz;
    }
    if (maps.present.w != 0u) {
        t.emission = textureSampleGrad(t_emission, s_emission, map_uv(3u, uv), map_d(3u, dx), map_d(3u, dy)).xyz;
    }
    if (maps.scalar.x != 0u) {
        let s = textureSampleGrad(t_shininess, s_shininess, map_uv(4u, uv), map_d(4u, dx), map_d(4u, dy));
        t.shininess = channel(maps.scalar.z, s);
    }
    if (maps.scalar.y != 0u) {
        let a = textureSampleGrad(t_alpha, s_alpha, map_uv(5u, uv), map_d(5u, dx), map_d(5u, dy));
        t.alpha = channel(maps.scalar.w, a);
    }
    if (maps.normal.x != 0.0) {
        let n = textureSampleGrad(t_normal, s_normal, map_uv(6u, uv), map_d(6u, dx), map_d(6u, dy)).xyz * 2.0 - 1.0;
        t.normal = vec3<f32>(n.x * maps.normal.y, select(n.y, -n.y, maps.normal.z != 0.0) * maps.normal.y, n.z);
    }
    if (maps.pbr.w != 0.0) {
        let o = textureSampleGrad(t_occlusion, s_occlusion, map_uv(8u, uv), map_d(8u, dx), map_d(8u, dy)).x;
        t.occlusion = 1.0 + maps.base.w * (o - 1.0);
    }
    // A metallic-roughness map: the diffuse, specular and shininess texels of phong-core's
    // `MetalRough`.
    if (maps.pbr.x != 0.0) {
        let s = textureSampleGrad(t_metal_rough, s_metal_rough, map_uv(7u, uv), map_d(7u, dx), map_d(7u, dy));
        let m = clamp(maps.pbr.y * s.z, 0.0, 1.0);
        let base = maps.base.xyz * t.diffuse.xyz;
        t.specular = vec3<f32>(0.04 * (1.0 - m)) + base * m;
        t.shininess = roughness_shininess(maps.pbr.z * s.y);
        t.diffuse = vec4<f32>(t.diffuse.xyz * (1.0 - m), t.diffuse.w);
    }
    return t;
}

// Lit::modulate with no ambient or emission of their own: clamp(P·T_Kd + S·T_Ks).
fn modulate(p: vec3<f32>, s: vec3<f32>, t: Texels, clamped: bool) -> vec3<f32> {
    let c = finite_or_zero(p * t.diffuse.xyz + s * t.specular);
    if (clamped) {
        return clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    return c;
}

// A textured object's colour (see phong-core's `shade_textured`).
fn textured(f: VsOut, back: bool, t: Texels) -> vec3<f32> {
    let o = objects[f.object];
    let output = o.options.mode.y;
    let interpolation = o.options.mode.x;
    let clamped = o.options.flags.y != 0u;
    if (output >= 4u) {
        return fragment(f, back);
    }
    if (interpolation == 0u) {
        return modulate(select(f.flat_color, f.flat_back, back), select(f.flat_spec, f.flat_spec_back, back), t, clamped);
    }
    if (interpolation == 1u) {
        return modulate(select(f.color, f.color_back, back), select(f.spec, f.spec_back, back), t, clamped);
    }
    var normal = f.normal;
    if (back) {
        normal = -normal;
    }
    // A normal map tilts the normal in the tangent frame (phong-core's `perturb`).
    if (maps.normal.x != 0.0) {
        let nn = normalize_or_zero(normal);
        let tt = normalize_or_zero(f.tangent.xyz - nn * dot(nn, f.tangent.xyz));
        if (any(tt != vec3<f32>(0.0)) && any(nn != vec3<f32>(0.0))) {
            let b = cross(nn, tt) * select(1.0, -1.0, f.tangent.w < 0.0);
            normal = tt * t.normal.x + b * t.normal.y + nn * t.normal.z;
        }
    }
    var m = o.material;
    let e = m.emission.xyz;
    m.emission = vec4<f32>(0.0, 0.0, 0.0, m.emission.w * max(t.shininess, 0.0));
    let s = shade(f.world, normal, m, raster_options(o), frame.ambient.xyz, frame.counts.x);
    let td = t.diffuse.xyz;
    var p = s.diffuse;
    var q = vec3<f32>(0.0);
    var te = td;
    var ta = td;
    if (maps.present.w != 0u) {
        q += e * t.emission;
        te = t.emission;
    } else {
        p += e;
    }
    if (maps.present.y != 0u || maps.pbr.w != 0.0) {
        if (maps.present.y != 0u) {
            ta = t.ambient;
        }
        ta *= t.occlusion;
        q += s.ambient * ta;
    } else {
        p += s.ambient;
    }
    var pc = p;
    var sc = s.specular;
    if (clamped) {
        pc = clamp(pc, vec3<f32>(0.0), vec3<f32>(1.0));
        sc = clamp(sc, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    switch output {
        case 1u: { return finite_or_zero(e * te + s.ambient * ta); }
        case 2u: { return finite_or_zero(s.diffuse * td); }
        case 3u: { return finite_or_zero(s.specular * t.specular); }
        default: {
            let c = finite_or_zero(pc * td + q + sc * t.specular);
            if (clamped) {
                return clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
            }
            return c;
        }
    }
}

@fragment
fn fs_main(f: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // The coordinates' derivatives, in uniform control flow (the GPU's, per 2×2 quad).
    let dx = dpdx(f.uv);
    let dy = dpdy(f.uv);
    // Back faces are drawn only for two-sided objects (culled otherwise). Premultiplied, alpha
    // 1 but for blended objects; the read-back divides by the resolved alpha (straight alpha).
    if (maps.cutoff.z == 0.0) {
        let a = select(1.0, maps.cutoff.w, maps.blend.x != 0.0);
        return vec4<f32>(fragment(f, !front) * a, a);
    }
    var t = texels(f.uv, dx, dy);
    if (maps.blend.y != 0.0) {
        t.diffuse = vec4<f32>(t.diffuse.xyz * f.vcolor, t.diffuse.w);
    }
    let alpha = maps.cutoff.w * t.diffuse.w * t.alpha;
    if (maps.cutoff.y != 0.0 && alpha < maps.cutoff.x) {
        discard;
    }
    let a = select(1.0, alpha, maps.blend.x != 0.0);
    return vec4<f32>(textured(f, !front, t) * a, a);
}
