//! Diffuse and specular maps in the GLSL pair and the page, applied as phong applies them
//! (OpenGL's `GL_MODULATE` with `GL_SEPARATE_SPECULAR_COLOR`): the primary colour (emission,
//! ambient and diffuse terms) times the diffuse map's texel, plus the secondary colour (the
//! specular term) times the specular map's, each clamped first where the colour is clamped.
//! The page uploads phong's own mipmap levels, with the map's wrap and filters.

use crate::{Sampled, Unsupported};
use base64::Engine;
use phong_core::TextureMap;
use phong_core::{Filter, MipFilter, Wrap};
use phong_core::{Interpolation, Object, Output, ShadingSettings};
use serde_json::{Value, json};

/// `shadeSeparate`: the primary and secondary colours at a point, for the output asked.
fn separate(shading: &ShadingSettings) -> String {
    let clamp = shading.options.clamp;
    let (p, s) = match shading.output {
        Output::Color if clamp => ("clamp(a + d, 0.0, 1.0)", "clamp(sp, 0.0, 1.0)"),
        Output::Color => ("a + d", "sp"),
        Output::Ambient => ("a", "vec3(0.0)"),
        Output::Diffuse => ("d", "vec3(0.0)"),
        _ => ("vec3(0.0)", "sp"),
    };
    format!(
        "// The primary colour (emission, ambient and diffuse: modulated by the diffuse map) and the\n\
         // secondary (the specular term: by the specular map), as OpenGL separates them.\n\
         void shadeSeparate(vec3 P, vec3 N, out vec3 primary, out vec3 secondary) {{\n    \
         vec3 a, d, sp;\n    lightPoint(P, N, a, d, sp);\n    primary = {p};\n    secondary = {s};\n}}\n"
    )
}

/// The maps' uniforms and `modulate(primary, secondary, uv)`.
fn modulate(shading: &ShadingSettings, sampled: Sampled) -> String {
    let mut s = String::new();
    let texel = |name: &str, has: bool| {
        if has {
            format!("texture(u{name}Map, (u{name}Uv * vec3(uv, 1.0)).xy).rgb")
        } else {
            "vec3(1.0)".to_string()
        }
    };
    if sampled.diffuse {
        s += "uniform sampler2D uDiffuseMap;\nuniform mat3 uDiffuseUv;\n";
    }
    if sampled.specular {
        s += "uniform sampler2D uSpecularMap;\nuniform mat3 uSpecularUv;\n";
    }
    let sum = "primary * tKd + secondary * tKs";
    let result = if shading.output == Output::Color && shading.options.clamp {
        format!("clamp({sum}, 0.0, 1.0)")
    } else {
        sum.to_string()
    };
    s + &format!(
        "// GL_MODULATE with a separate specular colour: texels are linear values; a map's `uv`\n\
         // transform (scale, rotation, offset) is its uDiffuseUv / uSpecularUv.\n\
         vec3 modulate(vec3 primary, vec3 secondary, vec2 uv) {{\n    vec3 tKd = {};\n    vec3 tKs = {};\n    return {result};\n}}\n",
        texel("Diffuse", sampled.diffuse),
        texel("Specular", sampled.specular)
    )
}

fn encode_of(lighting: &str) -> &'static str {
    if lighting.contains("lessThanEqual(c, vec3(0.0031308))") {
        "vec3 encode(vec3 c) {\n    c = clamp(c, 0.0, 1.0);\n    return mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, 12.92 * c, vec3(lessThanEqual(c, vec3(0.0031308))));\n}\n"
    } else {
        "vec3 encode(vec3 c) {\n    return clamp(c, 0.0, 1.0);\n}\n"
    }
}

/// Phong interpolation with maps: lit and textured per fragment.
pub(crate) fn per_fragment(lighting: &str, shading: &ShadingSettings, sampled: Sampled) -> (String, String) {
    let vertex = "// Phong interpolation: the position, normal (world space) and texture coordinates go to\n\
                  // the fragment shader.\n\
                  uniform mat4 uClipFromWorld;\nin vec3 position;\nin vec3 normal;\nin vec2 uv;\n\
                  out vec3 vPosition;\nout vec3 vNormal;\nout vec2 vUv;\n\
                  void main() {\n    vPosition = position;\n    vNormal = normal;\n    vUv = uv;\n    \
                  gl_Position = uClipFromWorld * vec4(position, 1.0);\n}\n"
        .to_string();
    let flip = if shading.options.two_sided {
        "    vec3 N = gl_FrontFacing ? vNormal : -vNormal;\n"
    } else {
        "    vec3 N = vNormal;\n"
    };
    let fragment = format!(
        "{lighting}\n{}\n{}\nin vec3 vPosition;\nin vec3 vNormal;\nin vec2 vUv;\nout vec4 fragColor;\n\
         void main() {{\n{flip}    vec3 primary, secondary;\n    shadeSeparate(vPosition, N, primary, secondary);\n    \
         fragColor = vec4(encode(modulate(primary, secondary, vUv)), 1.0);\n}}\n",
        separate(shading),
        modulate(shading, sampled)
    );
    (vertex, fragment)
}

/// Gouraud and flat interpolation with maps: the primary and secondary colours lit at the
/// vertices (flat: at the triangle's centroid, `flat` varyings), the maps sampled per fragment.
pub(crate) fn per_vertex(lighting: &str, shading: &ShadingSettings, sampled: Sampled) -> (String, String) {
    let two = shading.options.two_sided;
    let flat = shading.interpolation == Interpolation::Flat;
    let q = if flat { "flat " } else { "" };
    let at = if flat { "triangleCentroid" } else { "position" };
    let vertex = format!(
        "{lighting}\n{}\n// {} the colours are computed here, the maps sampled per fragment.\n\
         uniform mat4 uClipFromWorld;\nin vec3 position;\nin vec3 normal;\nin vec2 uv;\n{}\
         {q}out vec3 vPrimary;\n{q}out vec3 vSecondary;\n{q}out vec3 vBackPrimary;\n{q}out vec3 vBackSecondary;\nout vec2 vUv;\n\
         void main() {{\n    shadeSeparate({at}, normal, vPrimary, vSecondary);\n{}    vUv = uv;\n    \
         gl_Position = uClipFromWorld * vec4(position, 1.0);\n}}\n",
        separate(shading),
        if flat {
            "Flat interpolation: each triangle lit at its centroid with its facet normal;"
        } else {
            "Gouraud interpolation:"
        },
        if flat { "in vec3 triangleCentroid;\n" } else { "" },
        if two {
            format!("    shadeSeparate({at}, -normal, vBackPrimary, vBackSecondary);\n")
        } else {
            "    vBackPrimary = vPrimary;\n    vBackSecondary = vSecondary;\n".to_string()
        },
    );
    let pick = if two { "gl_FrontFacing ? " } else { "true ? " };
    let fragment = format!(
        "{}\n{}\n{q}in vec3 vPrimary;\n{q}in vec3 vSecondary;\n{q}in vec3 vBackPrimary;\n{q}in vec3 vBackSecondary;\nin vec2 vUv;\n\
         out vec4 fragColor;\nvoid main() {{\n    vec3 primary = {pick}vPrimary : vBackPrimary;\n    \
         vec3 secondary = {pick}vSecondary : vBackSecondary;\n    \
         fragColor = vec4(encode(modulate(primary, secondary, vUv)), 1.0);\n}}\n",
        modulate(shading, sampled),
        encode_of(lighting),
    );
    (vertex, fragment)
}

/// The maps' `uv` transforms as `mat3` uniforms (column-major, affine).
pub(crate) fn uv_uniforms(o: &Object, u: &mut Value) {
    for (name, map) in [("uDiffuseUv", &o.maps.diffuse), ("uSpecularUv", &o.maps.specular)] {
        if let Some(m) = map {
            let (l, t) = (m.transform.linear, m.transform.offset);
            u[name] = json!([l.x_axis.x, l.x_axis.y, 0.0, l.y_axis.x, l.y_axis.y, 0.0, t.x, t.y, 1.0]);
        }
    }
}

/// GL's wrap, magnification and minification enums for a map.
fn gl_sampler(m: &TextureMap) -> Value {
    let s = &m.sampler;
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => 10497,
        Wrap::Clamp => 33071,
        Wrap::Mirror => 33648,
    };
    let mag = match s.mag {
        Filter::Nearest => 9728,
        Filter::Linear => 9729,
    };
    let min = match (s.min, s.mip) {
        (Filter::Nearest, MipFilter::None) => 9728,
        (Filter::Linear, MipFilter::None) => 9729,
        (Filter::Nearest, MipFilter::Nearest) => 9984,
        (Filter::Linear, MipFilter::Nearest) => 9985,
        (Filter::Nearest, MipFilter::Linear) => 9986,
        (Filter::Linear, MipFilter::Linear) => 9987,
    };
    json!({"wrapS": wrap(s.wrap_u), "wrapT": wrap(s.wrap_v), "mag": mag, "min": min})
}

/// What a program's user binds: each map's size and GL sampler state (texture unit 0 the
/// diffuse map, 1 the specular map).
pub(crate) fn describe(o: &Object) -> Value {
    let one = |m: &Option<TextureMap>, unit: u32| {
        m.as_ref().map(|m| {
            let mut v = gl_sampler(m);
            v["unit"] = json!(unit);
            v["width"] = json!(m.texture.width());
            v["height"] = json!(m.texture.height());
            v
        })
    };
    json!({"diffuse": one(&o.maps.diffuse, 0), "specular": one(&o.maps.specular, 1)})
}

/// `x` (in [0, 65504]) as a half float's bits, rounded to nearest.
fn half(x: f32) -> u16 {
    let b = x.to_bits();
    let sign = ((b >> 16) & 0x8000) as u16;
    let exp = ((b >> 23) & 0xff) as i32 - 127 + 15;
    let mant = b & 0x7f_ffff;
    if x == 0.0 {
        return sign;
    }
    if exp <= 0 {
        // Subnormal half.
        let m = (mant | 0x80_0000) >> (1 - exp).min(31);
        return sign | ((m + 0x1000) >> 13) as u16;
    }
    if exp >= 31 {
        return sign | 0x7bff;
    }
    let rounded = ((exp as u32) << 10 | (mant >> 13)) + u32::from(mant & 0x1fff > 0x1000 || (mant & 0x3fff) == 0x3000);
    sign | rounded.min(0x7bff) as u16
}

/// A map's image for the page: phong's mipmap levels (rows from the bottom, as GL takes them),
/// 8-bit as bytes, 16-bit as half floats, with its sampler state.
pub(crate) fn page_data(m: &TextureMap) -> Result<Value, Unsupported> {
    let b64 = |bytes: Vec<u8>| base64::engine::general_purpose::STANDARD.encode(bytes);
    let t = &m.texture;
    let mut levels = Vec::new();
    for i in 0..t.level_count() {
        if let Some((w, h, texels)) = t.level8(i) {
            levels.push(json!({"width": w, "height": h, "data": b64(texels.iter().flatten().copied().collect())}));
        } else if let Some((w, h, texels)) = t.level16(i) {
            let bytes = texels
                .iter()
                .flatten()
                .flat_map(|&c| half(f32::from(c) / 65535.0).to_le_bytes())
                .collect();
            levels.push(json!({"width": w, "height": h, "data": b64(bytes)}));
        } else {
            return Err(Unsupported("a texture of a storage the page cannot upload".into()));
        }
    }
    let mut v = gl_sampler(m);
    v["half"] = json!(t.bits() == 16);
    v["levels"] = json!(levels);
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::half;

    #[test]
    fn half_floats_round_to_nearest() {
        assert_eq!(half(1.0), 0x3c00);
        assert_eq!(half(0.5), 0x3800);
        assert_eq!(half(0.0), 0);
        // 1/3 is 0x3555 in half precision (0.33325).
        assert_eq!(half(1.0 / 3.0), 0x3555);
        // Below half's smallest normal: subnormal.
        assert_eq!(half(2f32.powi(-24)), 1);
        for k in 0..=255u16 {
            let x = f32::from(k) / 255.0;
            let h = half(x);
            let back = f32::from(h & 0x3ff) / 1024.0 + 1.0;
            let e = i32::from(h >> 10) - 15;
            let y = if h >> 10 == 0 {
                f32::from(h) * 2f32.powi(-24)
            } else {
                back * 2f32.powi(e)
            };
            assert!((x - y).abs() <= x * 2f32.powi(-11) + 1e-7, "{x} -> {h:#x} = {y}");
        }
    }
}
