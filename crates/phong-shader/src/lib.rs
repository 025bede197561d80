//! # phong-shader
//!
//! A scene's illumination model as shaders: a vertex/fragment pair in GLSL 1.20 (the form the
//! course's notes use), GLSL 3.30 core and GLSL ES 3.00, and a standalone WebGL2 page that
//! draws the scene's meshes with them. The shaders compute [`phong_core::shade`] term for term
//! (the equation is in their comments); the scene's model, options, light count and kinds are
//! compiled in, the colours, positions and matrices are uniforms whose values come as JSON.
//!
//! What a shader cannot express exactly is refused ([`Unsupported`]) instead of drawn
//! differently: texture maps, blending, the normal and depth outputs; a GLSL pair has one
//! shading, so a scene whose objects are shaded differently is exported one object at a time
//! (the page draws each with its own program).

use base64::Engine;
use glam::Vec3;
use phong_core::{
    Encoding, Interpolation, Light, LyonLambda, Normalization, Object, Output, Scene, ShadingSettings, SpecularModel,
    Viewer,
};
use serde_json::{Value, json};
use std::fmt::Write;

mod brdf;
mod page;
mod texture;
mod three;
mod wgsl;
pub use brdf::brdf;
pub use page::html;
pub use three::threejs;
pub use wgsl::buffers as wgsl_buffers;

/// Why a scene cannot be exported exactly.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Unsupported(pub String);

/// The GLSL dialect.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Version {
    /// GLSL 1.20 (`attribute`, `varying`, `gl_FragColor`): the course's form.
    Legacy120,
    /// GLSL 3.30 core.
    Core330,
    /// GLSL ES 3.00 (WebGL2).
    Es300,
}

/// A vertex/fragment pair and the values of its uniforms.
#[derive(Clone, Debug)]
pub struct Program {
    /// The vertex shader.
    pub vertex: String,
    /// The fragment shader.
    pub fragment: String,
    /// `{"scene": {uniform: value}, "objects": [{"name", "uniforms": {...}}]}`.
    pub uniforms: Value,
}

/// The maps an object's shaders sample: its diffuse and specular maps (OpenGL's
/// `GL_MODULATE` with a separate specular colour, as phong applies them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Sampled {
    pub diffuse: bool,
    pub specular: bool,
}

impl Sampled {
    pub(crate) fn of(o: &Object) -> Sampled {
        Sampled {
            diffuse: o.maps.diffuse.is_some(),
            specular: o.maps.specular.is_some(),
        }
    }

    fn any(self) -> bool {
        self.diffuse || self.specular
    }
}

/// Why object `o` cannot be drawn by an exported shader, if it cannot; `maps`: whether the
/// target draws diffuse and specular maps.
fn check_object(o: &Object, maps: bool) -> Result<(), Unsupported> {
    let m = &o.maps;
    let others = [
        (m.ambient.is_some(), "ambient (map_Ka)"),
        (m.emission.is_some(), "emission (map_Ke)"),
        (m.shininess.is_some(), "shininess (map_Ns)"),
        (
            m.alpha.is_some() || m.alpha_cutoff.is_some(),
            "alpha (map_d, the alpha test)",
        ),
        (m.normal.is_some(), "normal or bump"),
        (m.metal_rough.is_some(), "metallic-roughness"),
        (m.occlusion.is_some(), "occlusion"),
    ];
    let unsupported: Vec<&str> = others.iter().filter(|(has, _)| *has).map(|(_, what)| *what).collect();
    if !unsupported.is_empty() {
        return Err(Unsupported(format!(
            "object `{}` has {} maps: the shader export draws diffuse and specular maps only",
            o.name,
            unsupported.join(", ")
        )));
    }
    if Sampled::of(o).any() && !maps {
        return Err(Unsupported(format!(
            "object `{}` has texture maps: this target draws untextured materials (the glsl and html targets draw diffuse and specular maps)",
            o.name
        )));
    }
    if [&m.diffuse, &m.specular].into_iter().flatten().any(|t| t.set != 0) {
        return Err(Unsupported(format!(
            "object `{}`: a map on the second texture coordinates (TEXCOORD_1): the shader export reads the first",
            o.name
        )));
    }
    if o.blends() {
        return Err(Unsupported(format!(
            "object `{}` is transparent (blended): the shader export draws opaque objects only",
            o.name
        )));
    }
    if matches!(o.shading.output, Output::Normal | Output::Depth) {
        return Err(Unsupported(format!(
            "object `{}`: output {:?}: the shader export draws the lit colour and its terms (color, ambient, diffuse, specular)",
            o.name, o.shading.output
        )));
    }
    Ok(())
}

/// The shading every object of `scene` shares, or why there is none.
fn shared_shading(scene: &Scene, maps: bool) -> Result<ShadingSettings, Unsupported> {
    let first = scene
        .objects
        .first()
        .ok_or_else(|| Unsupported("the scene has no objects".into()))?;
    for o in &scene.objects {
        check_object(o, maps)?;
        if o.shading != first.shading || Sampled::of(o) != Sampled::of(first) {
            return Err(Unsupported(format!(
                "objects `{}` and `{}` are shaded differently (model, interpolation, viewer, output or maps): \
                 a program has one; choose one with --object (the html target draws each with its own)",
                first.name, o.name
            )));
        }
    }
    Ok(first.shading)
}

fn v3(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn rgb(c: phong_core::Color) -> Value {
    json!([c.r, c.g, c.b])
}

/// The uniforms of the scene (camera, global ambient, lights).
pub(crate) fn scene_uniforms(scene: &Scene) -> Value {
    let aspect = scene.image.width as f32 / scene.image.height as f32;
    let m = scene.camera.clip_from_world(aspect).to_cols_array();
    let lights = scene.lighting.lights();
    let each = |f: &dyn Fn(&Light) -> Value| Value::Array(lights.iter().map(f).collect());
    json!({
        "uClipFromWorld": m,
        "uEye": v3(scene.camera.eye()),
        "uToViewer": v3((scene.camera.eye() - scene.camera.target()).normalize_or_zero()),
        "uGlobalAmbient": rgb(scene.lighting.ambient()),
        "uLightPosition": each(&|l| v3(l.position().or_else(|| l.to_light()).unwrap_or(Vec3::ZERO))),
        "uLightAttenuation": each(&|l| json!(l.attenuation().unwrap_or_default().coefficients())),
        "uLightAmbient": each(&|l| rgb(l.color().ambient())),
        "uLightDiffuse": each(&|l| rgb(l.color().diffuse())),
        "uLightSpecular": each(&|l| rgb(l.color().specular())),
        "uSpotDirection": each(&|l| v3(l.spot_cone().map_or(Vec3::ZERO, |c| c.0))),
        "uSpotCosCutoff": each(&|l| json!(l.spot_cone().map_or(-2.0, |c| c.2))),
        "uSpotExponent": each(&|l| json!(l.spot_cone().map_or(0.0, |c| c.3))),
    })
}

/// The uniforms of one object's material (`k_d`, `k_s` from the normalisation).
fn material_uniforms(o: &Object) -> Value {
    let m = &o.material;
    let s = m.shininess();
    let (kd, ks) = o.shading.options.normalization.factors(s);
    json!({
        "uEmission": rgb(m.emission()),
        "uAmbient": rgb(m.ambient()),
        "uDiffuse": rgb(m.diffuse()),
        "uSpecular": rgb(m.specular()),
        "uShininess": s,
        "uKd": kd,
        "uKs": ks,
    })
}

/// The exact shaders for `scene` in `version` (its objects all shaded alike), or why it
/// cannot be exported.
pub fn program(scene: &Scene, version: Version) -> Result<Program, Unsupported> {
    let shading = shared_shading(scene, true)?;
    Ok(program_for(
        scene,
        &shading,
        &scene.objects.iter().collect::<Vec<_>>(),
        version,
    ))
}

/// The shaders of object `index` of `scene` (by its shading), with its uniforms only.
pub fn program_of(scene: &Scene, index: usize, version: Version) -> Result<Program, Unsupported> {
    let o = scene
        .objects
        .get(index)
        .ok_or_else(|| Unsupported(format!("the scene has no object {index}")))?;
    check_object(o, true)?;
    Ok(program_for(scene, &o.shading, &[o], version))
}

/// The scene's model as one WGSL module (`vs_main`, `fs_main`; see the `wgsl` module's
/// bindings): the scene's, whose objects must share one shading, or object `index`'s.
pub fn wgsl(scene: &Scene, index: Option<usize>) -> Result<String, Unsupported> {
    let shading = match index {
        None => shared_shading(scene, false)?,
        Some(i) => {
            let o = scene
                .objects
                .get(i)
                .ok_or_else(|| Unsupported(format!("the scene has no object {i}")))?;
            check_object(o, false)?;
            o.shading
        }
    };
    Ok(wgsl::module(scene, &shading))
}

/// The program of `shading` for `objects` (which are shaded so).
fn program_for(scene: &Scene, shading: &ShadingSettings, objects: &[&Object], version: Version) -> Program {
    let sampled = objects.first().map_or(Sampled::default(), |o| Sampled::of(o));
    let lighting = lighting_glsl(scene, shading);
    let (vertex, fragment) = match (shading.interpolation, sampled.any()) {
        (Interpolation::Gouraud, false) => gouraud(&lighting, shading, false),
        (Interpolation::Flat, false) => gouraud(&lighting, shading, true),
        (Interpolation::Phong, false) => per_fragment(&lighting, shading),
        (Interpolation::Phong, true) => texture::per_fragment(&lighting, shading, sampled),
        (_, true) => texture::per_vertex(&lighting, shading, sampled),
    };
    let uniforms = json!({
        "scene": scene_uniforms(scene),
        "objects": objects.iter().map(|o| {
            let mut u = material_uniforms(o);
            texture::uv_uniforms(o, &mut u);
            json!({"name": o.name, "uniforms": u, "maps": texture::describe(o)})
        }).collect::<Vec<_>>(),
    });
    Program {
        vertex: dialect(&vertex, version, true),
        fragment: dialect(&fragment, version, false),
        uniforms,
    }
}

/// The source, written as GLSL 3.30 with `#version` left out, in `version`'s words.
fn dialect(src: &str, version: Version, vertex: bool) -> String {
    match version {
        Version::Core330 => format!("#version 330 core\n{src}"),
        Version::Es300 => format!("#version 300 es\nprecision highp float;\n{src}"),
        Version::Legacy120 => {
            let mut out = String::from("#version 120\n");
            for line in src.lines() {
                let line = line
                    .replace("flat out ", "out ")
                    .replace("flat in ", "in ")
                    .replace("texture(", "texture2D(");
                let line = line.as_str();
                let l = if vertex {
                    line.replacen("in ", "attribute ", usize::from(line.starts_with("in ")))
                        .replacen("out ", "varying ", usize::from(line.starts_with("out ")))
                } else if line.starts_with("out vec4 fragColor") {
                    continue;
                } else {
                    line.replacen("in ", "varying ", usize::from(line.starts_with("in ")))
                        .replace("fragColor", "gl_FragColor")
                };
                out.push_str(&l);
                out.push('\n');
            }
            out
        }
    }
}

/// The header comment: the equation the shaders compute, in the seed's words.
fn equation(shading: &ShadingSettings) -> String {
    let o = &shading.options;
    let spec = match o.specular {
        SpecularModel::None => "0 (Lambert: no highlight)".to_string(),
        SpecularModel::Phong => "((R.V)+)^s, R = 2(N.L)N - L (Phong 1973)".to_string(),
        SpecularModel::BlinnPhong => "((N.H)+)^s, H = normalize(L + V) (Blinn 1977, OpenGL's)".to_string(),
        SpecularModel::Lyon { squarings, .. } => {
            format!("(1 - (s/g) lambda)+^g, g = 2^{squarings}, lambda = 1 - R.V, only where R.V > 0 (Lyon 1993)")
        }
    };
    format!(
        "// Generated by `phong shader`: the Phong illumination model of this scene, exactly as\n\
         // phong computes it (phong-core's `shade`). In the course's words:\n\
         //   colour = ambient + diffuse + specular\n\
         //   ambient  = e_m + a_m*a_g + sum_lights att*spot * a_m*a_l\n\
         //   diffuse  = sum_lights att*spot * k_d (N.L)+ d_m*d_l\n\
         //   specular = sum_lights att*spot * k_s f spec s_m*s_l\n\
         // with (x)+ = max(x, 0), spec = {spec},\n\
         // f = {gate}, k_d = uKd, k_s = uKs{norm}; att = 1/(k0 + k1 d + k2 d^2) for point and spot\n\
         // lights, spot = (-L.S)^exponent inside the cone. N, L, V are unit vectors in world space;\n\
         // V points to the {viewer}. The colour is {clamp}.\n",
        gate = if o.gate_specular {
            "1 where N.L > 0, else 0"
        } else {
            "1"
        },
        norm = if o.normalization == Normalization::None {
            " (1: not normalised)"
        } else {
            " (energy normalisation; the specular term also times (N.L)+)"
        },
        viewer = match shading.viewer {
            Viewer::Local => "eye (local viewer)",
            Viewer::Infinite => "camera along its axis (infinite viewer)",
        },
        clamp = if o.clamp { "clamped to [0, 1]" } else { "not clamped" },
    )
}

/// The GLSL that sets `float spec` from unit `L`, `N`, `V` and `uShininess`, for `o`'s model.
fn specular_code(o: &phong_core::ShadingOptions) -> String {
    match o.specular {
        SpecularModel::None => "    float spec = 0.0;\n".to_string(),
        SpecularModel::Phong => "    vec3 R = 2.0 * dot(L, N) * N - L;\n    float spec = powPositive(dot(R, V), uShininess);\n".to_string(),
        SpecularModel::BlinnPhong => "    vec3 LV = L + V;\n    float spec = dot(LV, LV) > 0.0 ? powPositive(dot(N, normalize(LV)), uShininess) : 0.0;\n".to_string(),
        SpecularModel::Lyon { squarings, lambda } => {
            let lam = match lambda {
                LyonLambda::Dot => "1.0 - rv",
                LyonLambda::Difference => "0.5 * dot(R - V, R - V)",
            };
            let k = squarings.min(16);
            format!(
                "    vec3 R = 2.0 * dot(L, N) * N - L;\n    float rv = dot(R, V);\n    float spec = 0.0;\n    if (rv > 0.0) {{\n        float g = {g:.1};\n        spec = max(1.0 - (uShininess / g) * max({lam}, 0.0), 0.0);\n        for (int k = 0; k < {k}; k++) spec *= spec;\n    }}\n",
                g = f64::from(1u32 << k)
            )
        }
    }
}

/// The uniform declarations and the `light(P, N, out ambient, out diffuse, out specular)`
/// function: every light's code, its kind compiled in.
fn lighting_glsl(scene: &Scene, shading: &ShadingSettings) -> String {
    let o = &shading.options;
    let lights = scene.lighting.lights();
    let n = lights.len();
    let mut s = equation(shading);
    s += "uniform vec3 uEmission, uAmbient, uDiffuse, uSpecular;\n\
          uniform float uShininess, uKd, uKs;\n\
          uniform vec3 uEye, uToViewer, uGlobalAmbient;\n";
    if n > 0 {
        let _ = write!(
            s,
            "uniform vec3 uLightPosition[{n}], uLightAttenuation[{n}], uLightAmbient[{n}], uLightDiffuse[{n}], uLightSpecular[{n}], uSpotDirection[{n}];\n\
             uniform float uSpotCosCutoff[{n}], uSpotExponent[{n}];\n"
        );
    }
    s += "\n// (x+)^s with 0^s = 0, x taken as at most 1 against rounding.\n\
          float powPositive(float x, float s) { return x > 0.0 ? pow(min(x, 1.0), s) : 0.0; }\n\n";
    let spec = specular_code(o);
    let _ = write!(
        s,
        "// One light's share: att*spot, the direction to it, and the three terms.\n\
         void addLight(vec3 L, float att, vec3 N, vec3 V, vec3 la, vec3 ld, vec3 ls, inout vec3 a, inout vec3 d, inout vec3 sp) {{\n\
         \x20   if (!(att > 0.0)) return;\n\
         \x20   a += uAmbient * la * att;\n\
         \x20   if (dot(L, L) == 0.0 || dot(N, N) == 0.0) return;\n\
         \x20   float nl = dot(N, L);\n\
         \x20   if (nl > 0.0) d += uDiffuse * ld * (att * uKd * nl);\n\
         \x20   {gate}\n\
         \x20   if (dot(V, V) == 0.0) return;\n\
         {spec}{norm}\
         \x20   if (spec > 0.0) sp += uSpecular * ls * (att * uKs * spec);\n\
         }}\n\n",
        gate = if o.gate_specular { "else return;" } else { "" },
        norm = if o.normalization == Normalization::None {
            ""
        } else {
            "    spec *= max(nl, 0.0);\n"
        },
    );
    s += "// The terms at point P with normal Nraw (any length), world space.\n\
          void lightPoint(vec3 P, vec3 Nraw, out vec3 a, out vec3 d, out vec3 sp) {\n";
    s += match shading.viewer {
        Viewer::Local => "    vec3 V = uEye - P;\n",
        Viewer::Infinite => "    vec3 V = uToViewer;\n",
    };
    s += "    V = dot(V, V) > 0.0 ? normalize(V) : vec3(0.0);\n\
          \x20   vec3 N = dot(Nraw, Nraw) > 0.0 ? normalize(Nraw) : vec3(0.0);\n\
          \x20   a = uEmission + uAmbient * uGlobalAmbient;\n\
          \x20   d = vec3(0.0);\n\
          \x20   sp = vec3(0.0);\n";
    for (i, l) in lights.iter().enumerate() {
        match l {
            Light::Directional(_) => {
                let _ = writeln!(
                    s,
                    "    // light {i}: directional\n    addLight(uLightPosition[{i}], 1.0, N, V, uLightAmbient[{i}], uLightDiffuse[{i}], uLightSpecular[{i}], a, d, sp);"
                );
            }
            _ => {
                let spot = if l.spot_cone().is_some_and(|c| c.1 != 180.0) {
                    format!(
                        "        if (dist > 0.0) {{\n            float c = dot(-L, uSpotDirection[{i}]);\n            att *= c >= uSpotCosCutoff[{i}] ? pow(max(c, 0.0), uSpotExponent[{i}]) : 0.0;\n        }}\n"
                    )
                } else {
                    String::new()
                };
                let _ = write!(
                    s,
                    "    {{ // light {i}: {kind}\n\
                     \x20       vec3 toLight = uLightPosition[{i}] - P;\n\
                     \x20       float dist = length(toLight);\n\
                     \x20       vec3 L = dist > 0.0 ? toLight / dist : vec3(0.0);\n\
                     \x20       vec3 k = uLightAttenuation[{i}];\n\
                     \x20       float att = 1.0 / (k.x + dist * (k.y + dist * k.z));\n\
                     {spot}\
                     \x20       addLight(L, att, N, V, uLightAmbient[{i}], uLightDiffuse[{i}], uLightSpecular[{i}], a, d, sp);\n\
                     \x20   }}\n",
                    kind = if spot.is_empty() { "point" } else { "spot" },
                );
            }
        }
    }
    s += "}\n\n";
    let _ = write!(
        s,
        "// The 8-bit value the image stores, as a colour in [0, 1].\n\
         vec3 encode(vec3 c) {{\n    c = clamp(c, 0.0, 1.0);\n{}}}\n\n",
        match scene.image.encoding {
            Encoding::Linear => "    return c;\n",
            Encoding::Srgb =>
                "    return mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, 12.92 * c, vec3(lessThanEqual(c, vec3(0.0031308))));\n",
        }
    );
    let term = match shading.output {
        Output::Color => {
            if o.clamp {
                "clamp(a + d + sp, 0.0, 1.0)"
            } else {
                "a + d + sp"
            }
        }
        Output::Ambient => "a",
        Output::Diffuse => "d",
        Output::Specular => "sp",
        Output::Normal | Output::Depth => unreachable!("refused by shared_shading"),
    };
    let _ = write!(
        s,
        "// What the image shows: {:?}.\nvec3 shadePoint(vec3 P, vec3 N) {{\n    vec3 a, d, sp;\n    lightPoint(P, N, a, d, sp);\n    return {term};\n}}\n",
        shading.output
    );
    s
}

/// Per-fragment (Phong) interpolation: world position and unnormalised normal interpolated,
/// lit per pixel; a back face of a two-sided object is lit with its normal flipped.
fn per_fragment(lighting: &str, shading: &ShadingSettings) -> (String, String) {
    let vertex = "// Phong interpolation: the position and normal (world space) go to the fragment shader.\n\
                  uniform mat4 uClipFromWorld;\n\
                  in vec3 position;\n\
                  in vec3 normal;\n\
                  out vec3 vPosition;\n\
                  out vec3 vNormal;\n\
                  void main() {\n\
                  \x20   vPosition = position;\n\
                  \x20   vNormal = normal;\n\
                  \x20   gl_Position = uClipFromWorld * vec4(position, 1.0);\n\
                  }\n"
    .to_string();
    let flip = if shading.options.two_sided {
        "    vec3 N = gl_FrontFacing ? vNormal : -vNormal;\n"
    } else {
        "    vec3 N = vNormal;\n"
    };
    let fragment = format!(
        "{lighting}\nin vec3 vPosition;\nin vec3 vNormal;\nout vec4 fragColor;\nvoid main() {{\n{flip}    fragColor = vec4(encode(shadePoint(vPosition, N)), 1.0);\n}}\n"
    );
    (vertex, fragment)
}

/// Per-vertex (Gouraud) interpolation: lit at the vertices, colours interpolated (both sides'
/// where lighting is two-sided, chosen per fragment by facing, as OpenGL does). Flat: each
/// triangle lit once at its centroid with its facet normal, as phong lights it: the mesh is
/// drawn with its vertices unshared, each carrying its triangle's `triangleCentroid` and facet
/// `normal`, and the colours are `flat`.
fn gouraud(lighting: &str, shading: &ShadingSettings, flat: bool) -> (String, String) {
    let two = shading.options.two_sided;
    let q = if flat { "flat " } else { "" };
    let (what, at) = if flat {
        (
            "// Flat interpolation: each triangle lit at its centroid with its facet normal (every\n\
             // vertex of a triangle carries both), one colour for the triangle.\n",
            "triangleCentroid",
        )
    } else {
        (
            "// Gouraud interpolation: the colour is computed here and interpolated.\n",
            "position",
        )
    };
    let vertex = format!(
        "{lighting}\n{what}uniform mat4 uClipFromWorld;\nin vec3 position;\nin vec3 normal;\n{}{q}out vec3 vFront;\n{}\
         void main() {{\n    vFront = shadePoint({at}, normal);\n{}    gl_Position = uClipFromWorld * vec4(position, 1.0);\n}}\n",
        if flat { "in vec3 triangleCentroid;\n" } else { "" },
        if two {
            format!("{q}out vec3 vBack;\n")
        } else {
            String::new()
        },
        if two {
            format!("    vBack = shadePoint({at}, -normal);\n")
        } else {
            String::new()
        },
    );
    let fragment = format!(
        "// The vertices' colours{}.\n\
         {q}in vec3 vFront;\n{}out vec4 fragColor;\n\
         vec3 encode(vec3 c) {{\n    c = clamp(c, 0.0, 1.0);\n{}}}\n\
         void main() {{\n    fragColor = vec4(encode({}), 1.0);\n}}\n",
        if flat { ", one a triangle" } else { ", interpolated" },
        if two {
            format!("{q}in vec3 vBack;\n")
        } else {
            String::new()
        },
        match lighting.contains("lessThanEqual(c, vec3(0.0031308))") {
            false => "    return c;\n",
            true =>
                "    return mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, 12.92 * c, vec3(lessThanEqual(c, vec3(0.0031308))));\n",
        },
        if two {
            "gl_FrontFacing ? vFront : vBack"
        } else {
            "vFront"
        },
    );
    (vertex, fragment)
}

/// The vertex arrays the shaders take for an object: `position`, `normal`, for flat objects
/// `triangleCentroid` (every vertex unshared, with its triangle's facet normal and centroid),
/// `uv` where the mesh has texture coordinates, and the triangles' indices.
#[derive(Clone, Debug, Default)]
pub struct VertexArrays {
    /// World-space positions.
    pub positions: Vec<Vec3>,
    /// World-space normals (facet normals for flat objects).
    pub normals: Vec<Vec3>,
    /// Each vertex's triangle's centroid (flat objects only, else empty).
    pub centroids: Vec<Vec3>,
    /// Texture coordinates (empty where the mesh has none).
    pub uvs: Vec<glam::Vec2>,
    /// Three indices a triangle.
    pub indices: Vec<u32>,
}

/// [`VertexArrays`] of object `o`.
pub fn vertex_arrays(o: &Object) -> VertexArrays {
    // (A flat mesh's triangles with vertices of their own: a vertex carries its normal.)
    let m = o.mesh.with_vertex_normals();
    if o.shading.interpolation != Interpolation::Flat {
        return VertexArrays {
            positions: m.positions().to_vec(),
            normals: m.normals().to_vec(),
            centroids: Vec::new(),
            uvs: m.uvs().to_vec(),
            indices: m.triangles().iter().flatten().copied().collect(),
        };
    }
    let mut out = VertexArrays::default();
    for (t, tri) in m.triangles().iter().enumerate() {
        let [a, b, c] = m.corners(t);
        let n = phong_core::mesh::facet_normal(a, b, c);
        let centroid = (a + b + c) / 3.0;
        for (p, &v) in [a, b, c].into_iter().zip(tri) {
            out.indices.push(out.positions.len() as u32);
            out.positions.push(p);
            out.normals.push(n);
            out.centroids.push(centroid);
            out.uvs.extend(m.uvs().get(v as usize));
        }
    }
    out
}

/// A mesh's arrays as base64 of little-endian values (positions, normals, centroids as
/// f32 × 3, texture coordinates f32 × 2, indices u32), for the page.
pub(crate) fn mesh_data(o: &Object, program: usize) -> Value {
    let b64 = |bytes: Vec<u8>| base64::engine::general_purpose::STANDARD.encode(bytes);
    let f = |v: &[Vec3]| b64(v.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect());
    let VertexArrays {
        positions,
        normals,
        centroids,
        uvs,
        indices,
    } = vertex_arrays(o);
    json!({
        "program": program,
        "positions": f(&positions),
        "normals": f(&normals),
        "centroids": f(&centroids),
        "uvs": b64(uvs.iter().flat_map(|t| t.to_array()).flat_map(f32::to_le_bytes).collect()),
        "indices": b64(indices.iter().flat_map(|i| i.to_le_bytes()).collect()),
        "count": indices.len(),
        "cull": !o.shading.options.two_sided,
    })
}
