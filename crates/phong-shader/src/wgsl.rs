//! The WGSL target: the same model as the GLSL pair, for WebGPU, as one module with a
//! `vs_main` and an `fs_main` entry point.
//!
//! Bindings: group 0, binding 0 the frame (`Frame`: the camera, the global ambient, the
//! lights), binding 1 the object's material (`Material`). Vertex inputs: `position` (0) and
//! `normal` (1) in world space, and for flat objects `triangle_centroid` (2). The uniforms'
//! values are the GLSL target's JSON; their byte layout is WGSL's for the structs below
//! (every `vec3` padded to 16 bytes by the scalar after it, or by a `pad`).

use crate::{equation, specular_code};
use phong_core::{Encoding, Interpolation, Light, Output, Scene, ShadingSettings, Viewer};
use std::fmt::Write;

/// The WGSL module of `shading` for `scene`'s lights.
pub(crate) fn module(scene: &Scene, shading: &ShadingSettings) -> String {
    let o = &shading.options;
    let lights = scene.lighting.lights();
    let n = lights.len().max(1);
    let mut s = equation(shading);
    let _ = write!(
        s,
        "\nstruct Light {{\n    position: vec3<f32>, spot_cos_cutoff: f32,\n    attenuation: vec3<f32>, spot_exponent: f32,\n    \
         ambient: vec3<f32>, pad0: f32,\n    diffuse: vec3<f32>, pad1: f32,\n    specular: vec3<f32>, pad2: f32,\n    \
         spot_direction: vec3<f32>, pad3: f32,\n}}\n\n\
         struct Frame {{\n    clip_from_world: mat4x4<f32>,\n    eye: vec3<f32>, pad0: f32,\n    to_viewer: vec3<f32>, pad1: f32,\n    \
         global_ambient: vec3<f32>, pad2: f32,\n    lights: array<Light, {n}>,\n}}\n\n\
         struct Material {{\n    emission: vec3<f32>, shininess: f32,\n    ambient: vec3<f32>, kd: f32,\n    \
         diffuse: vec3<f32>, ks: f32,\n    specular: vec3<f32>, pad0: f32,\n}}\n\n\
         @group(0) @binding(0) var<uniform> frame: Frame;\n\
         @group(0) @binding(1) var<uniform> material: Material;\n\n\
         // (x+)^s with 0^s = 0, x taken as at most 1 against rounding.\n\
         fn pow_positive(x: f32, s: f32) -> f32 {{\n    if (x > 0.0) {{ return pow(min(x, 1.0), s); }}\n    return 0.0;\n}}\n\n\
         struct Terms {{ a: vec3<f32>, d: vec3<f32>, s: vec3<f32> }}\n\n"
    );
    // The specular factor: the GLSL target's code, in WGSL's words.
    let spec = specular_code(o)
        .replace("uShininess", "material.shininess")
        .replace("vec3 ", "let ")
        .replace("float spec = 0.0;", "var spec = 0.0;")
        .replace("float spec =", "var spec: f32 =")
        .replace("float rv", "let rv")
        .replace("float g =", "let g: f32 =")
        .replace("for (int k = 0; k < ", "for (var k = 0; k < ")
        .replace("spec *= spec;", "{ spec *= spec; }")
        .replace(
            "dot(LV, LV) > 0.0 ? powPositive(dot(N, normalize(LV)), material.shininess) : 0.0",
            "select(0.0, pow_positive(dot(N, normalize(LV)), material.shininess), dot(LV, LV) > 0.0)",
        )
        .replace("powPositive", "pow_positive");
    let _ = write!(
        s,
        "// One light's share: att*spot, the direction to it, and the three terms.\n\
         fn add_light(L: vec3<f32>, att: f32, N: vec3<f32>, V: vec3<f32>, li: Light, t: ptr<function, Terms>) {{\n\
         \x20   if (!(att > 0.0)) {{ return; }}\n\
         \x20   (*t).a += material.ambient * li.ambient * att;\n\
         \x20   if (dot(L, L) == 0.0 || dot(N, N) == 0.0) {{ return; }}\n\
         \x20   let nl = dot(N, L);\n\
         \x20   if (nl > 0.0) {{ (*t).d += material.diffuse * li.diffuse * (att * material.kd * nl); }}{gate}\n\
         \x20   if (dot(V, V) == 0.0) {{ return; }}\n\
         {spec}{norm}\
         \x20   if (spec > 0.0) {{ (*t).s += material.specular * li.specular * (att * material.ks * spec); }}\n\
         }}\n\n",
        gate = if o.gate_specular { " else { return; }" } else { "" },
        norm = if o.normalization == phong_core::Normalization::None {
            ""
        } else {
            "    spec *= max(nl, 0.0);\n"
        },
    );
    s += "// The terms at point P with normal Nraw (any length), world space.\n\
          fn light_point(P: vec3<f32>, Nraw: vec3<f32>) -> Terms {\n";
    s += match shading.viewer {
        Viewer::Local => "    var V = frame.eye - P;\n",
        Viewer::Infinite => "    var V = frame.to_viewer;\n",
    };
    s += "    if (dot(V, V) > 0.0) { V = normalize(V); } else { V = vec3<f32>(0.0); }\n\
          \x20   var N = vec3<f32>(0.0);\n\
          \x20   if (dot(Nraw, Nraw) > 0.0) { N = normalize(Nraw); }\n\
          \x20   var t = Terms(material.emission + material.ambient * frame.global_ambient, vec3<f32>(0.0), vec3<f32>(0.0));\n";
    for (i, l) in lights.iter().enumerate() {
        match l {
            Light::Directional(_) => {
                let _ = writeln!(
                    s,
                    "    // light {i}: directional\n    add_light(frame.lights[{i}].position, 1.0, N, V, frame.lights[{i}], &t);"
                );
            }
            _ => {
                let spot = if l.spot_cone().is_some_and(|c| c.1 != 180.0) {
                    format!(
                        "        if (dist > 0.0) {{\n            let c = dot(-L, frame.lights[{i}].spot_direction);\n            \
                         att *= select(0.0, pow(max(c, 0.0), frame.lights[{i}].spot_exponent), c >= frame.lights[{i}].spot_cos_cutoff);\n        }}\n"
                    )
                } else {
                    String::new()
                };
                let _ = write!(
                    s,
                    "    {{ // light {i}: {kind}\n\
                     \x20       let to_light = frame.lights[{i}].position - P;\n\
                     \x20       let dist = length(to_light);\n\
                     \x20       var L = vec3<f32>(0.0);\n\
                     \x20       if (dist > 0.0) {{ L = to_light / dist; }}\n\
                     \x20       let k = frame.lights[{i}].attenuation;\n\
                     \x20       var att = 1.0 / (k.x + dist * (k.y + dist * k.z));\n\
                     {spot}\
                     \x20       add_light(L, att, N, V, frame.lights[{i}], &t);\n\
                     \x20   }}\n",
                    kind = if spot.is_empty() { "point" } else { "spot" },
                );
            }
        }
    }
    s += "    return t;\n}\n\n";
    let _ = write!(
        s,
        "// The 8-bit value the image stores, as a colour in [0, 1].\n\
         fn encode(c0: vec3<f32>) -> vec3<f32> {{\n    let c = clamp(c0, vec3<f32>(0.0), vec3<f32>(1.0));\n{}}}\n\n",
        match scene.image.encoding {
            Encoding::Linear => "    return c;\n",
            Encoding::Srgb =>
                "    return select(1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * c, c <= vec3<f32>(0.0031308));\n",
        }
    );
    let term = match shading.output {
        Output::Color if o.clamp => "clamp(t.a + t.d + t.s, vec3<f32>(0.0), vec3<f32>(1.0))",
        Output::Color => "t.a + t.d + t.s",
        Output::Ambient => "t.a",
        Output::Diffuse => "t.d",
        Output::Specular => "t.s",
        Output::Normal | Output::Depth => "vec3<f32>(0.0)",
    };
    let _ = write!(
        s,
        "// What the image shows: {:?}.\nfn shade_point(P: vec3<f32>, N: vec3<f32>) -> vec3<f32> {{\n    let t = light_point(P, N);\n    return {term};\n}}\n\n",
        shading.output
    );
    s + &entry_points(shading)
}

/// `vs_main` and `fs_main` for the interpolation.
fn entry_points(shading: &ShadingSettings) -> String {
    let two = shading.options.two_sided;
    let clip = "// The camera's matrix is OpenGL's (depth in [-w, w]); WebGPU's depth is in [0, w].\n\
                fn clip(position: vec3<f32>) -> vec4<f32> {\n    \
                let c = frame.clip_from_world * vec4<f32>(position, 1.0);\n    \
                return vec4<f32>(c.x, c.y, 0.5 * (c.z + c.w), c.w);\n}\n\n";
    clip.to_string()
        + &match shading.interpolation {
            Interpolation::Phong => format!(
                "// Phong interpolation: the position and normal (world space) go to the fragment stage.\n\
             struct Varyings {{\n    @builtin(position) clip: vec4<f32>,\n    @location(0) position: vec3<f32>,\n    @location(1) normal: vec3<f32>,\n}}\n\n\
             @vertex\nfn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> Varyings {{\n    \
             return Varyings(clip(position), position, normal);\n}}\n\n\
             @fragment\nfn fs_main(v: Varyings, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {{\n{}    \
             return vec4<f32>(encode(shade_point(v.position, N)), 1.0);\n}}\n",
                if two {
                    "    let N = select(-v.normal, v.normal, front);\n"
                } else {
                    "    let N = v.normal;\n"
                }
            ),
            flat_or_gouraud => {
                let flat = flat_or_gouraud == Interpolation::Flat;
                let q = if flat { " @interpolate(flat)" } else { "" };
                let (input, at) = if flat {
                    (", @location(2) triangle_centroid: vec3<f32>", "triangle_centroid")
                } else {
                    ("", "position")
                };
                format!(
                    "// {what}\n\
                 struct Varyings {{\n    @builtin(position) clip: vec4<f32>,\n    @location(0){q} front: vec3<f32>,\n    @location(1){q} back: vec3<f32>,\n}}\n\n\
                 @vertex\nfn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>{input}) -> Varyings {{\n    \
                 let front = shade_point({at}, normal);\n    let back = {back};\n    \
                 return Varyings(clip(position), front, back);\n}}\n\n\
                 @fragment\nfn fs_main(v: Varyings, @builtin(front_facing) facing: bool) -> @location(0) vec4<f32> {{\n    \
                 return vec4<f32>(encode({pick}), 1.0);\n}}\n",
                    what = if flat {
                        "Flat interpolation: each triangle lit at its centroid with its facet normal (every\n// vertex of a triangle carries both), one colour for the triangle."
                    } else {
                        "Gouraud interpolation: the colour is computed in the vertex stage and interpolated."
                    },
                    back = if two {
                        format!("shade_point({at}, -normal)")
                    } else {
                        "front".into()
                    },
                    pick = if two {
                        "select(v.back, v.front, facing)"
                    } else {
                        "v.front"
                    },
                )
            }
        }
}

/// The bytes of the `Frame` and `Material` uniforms of object `index` of `scene`, laid out as
/// the module declares them (little-endian f32).
pub fn buffers(scene: &Scene, index: usize) -> (Vec<u8>, Vec<u8>) {
    let mut frame: Vec<f32> = Vec::new();
    let aspect = scene.image.width as f32 / scene.image.height as f32;
    frame.extend(scene.camera.clip_from_world(aspect).to_cols_array());
    let to_viewer = (scene.camera.eye() - scene.camera.target()).normalize_or_zero();
    for (v, pad) in [
        (scene.camera.eye().to_array(), 0.0),
        (to_viewer.to_array(), 0.0),
        (scene.lighting.ambient().to_array(), 0.0),
    ] {
        frame.extend(v);
        frame.push(pad);
    }
    let lights = scene.lighting.lights();
    for l in lights {
        let (dir, cos_cutoff, exponent) = l.spot_cone().map_or((glam::Vec3::ZERO, -2.0, 0.0), |c| (c.0, c.2, c.3));
        let c = l.color();
        frame.extend(l.position().or_else(|| l.to_light()).unwrap_or_default().to_array());
        frame.push(cos_cutoff);
        frame.extend(l.attenuation().unwrap_or_default().coefficients());
        frame.push(exponent);
        for v in [
            c.ambient().to_array(),
            c.diffuse().to_array(),
            c.specular().to_array(),
            dir.to_array(),
        ] {
            frame.extend(v);
            frame.push(0.0);
        }
    }
    if lights.is_empty() {
        frame.extend([0.0; 24]);
    }
    let o = &scene.objects[index];
    let m = &o.material;
    let (kd, ks) = o.shading.options.normalization.factors(m.shininess());
    let mut material: Vec<f32> = Vec::new();
    for (c, x) in [
        (m.emission(), m.shininess()),
        (m.ambient(), kd),
        (m.diffuse(), ks),
        (m.specular(), 0.0),
    ] {
        material.extend(c.to_array());
        material.push(x);
    }
    let bytes = |v: Vec<f32>| v.into_iter().flat_map(f32::to_le_bytes).collect();
    (bytes(frame), bytes(material))
}
