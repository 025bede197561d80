//! MTL libraries: the names an `mtllib` statement gives, their text checked line by line (so
//! that errors have a line and column) and made readable by tobj, and their materials as
//! phong's.

use super::text::{Checker, lines};
use crate::Error;
use crate::texture_file::{MapRequest, parse_mtl_map};
use phong_core::{Color, Material};
use std::path::{Path, PathBuf};

/// The material libraries an `mtllib` statement names: first the whole text as one name
/// (tried first by the caller: a name with spaces in it), then each name, names separated by
/// whitespace except where it is quoted (`"my file.mtl"`) or escaped (`my\ file.mtl`); other
/// backslashes are path separators (`textures\\a.mtl`).
pub(super) fn mtl_names(text: &str) -> Vec<PathBuf> {
    let mut names = Vec::new();
    let mut whole = String::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = text.trim().chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => quoted = !quoted,
            '\\' if chars.peek().is_some_and(|n| n.is_whitespace()) => {
                let n = chars.next().unwrap_or(' ');
                cur.push(n);
                whole.push(n);
            }
            '\\' => {
                cur.push('/');
                whole.push('/');
            }
            c if c.is_whitespace() && !quoted => {
                if !cur.is_empty() {
                    names.push(PathBuf::from(std::mem::take(&mut cur)));
                }
                whole.push(c);
            }
            c => {
                cur.push(c);
                whole.push(c);
            }
        }
    }
    if !cur.is_empty() {
        names.push(PathBuf::from(cur));
    }
    let whole = PathBuf::from(whole.trim());
    if names.len() == 1 {
        return names;
    }
    names.insert(0, whole);
    names
}

/// The MTL text as tobj can read it: a colour given as one number (`Kd 0.5`, which the format
/// allows for grey) written as three, since tobj's reader panics on fewer than three.
pub(super) fn normalize_mtl(src: &str) -> String {
    let mut out = String::with_capacity(src.len() + 64);
    for line in src.split_inclusive('\n') {
        let content = line.split('#').next().unwrap_or("");
        let words: Vec<&str> = content.split_whitespace().collect();
        match words.as_slice() {
            [kw @ ("Ka" | "Kd" | "Ks" | "Ke"), v] => {
                out.push_str(&format!("{kw} {v} {v} {v}\n"));
            }
            // The optical density is not used; tobj would drop the whole library for a bad one.
            ["Ni", ..] => out.push('\n'),
            _ => out.push_str(line),
        }
    }
    out
}

/// Checks an MTL file's values; adds the warnings (unsupported `illum`, texture statements and
/// options not used) and each material's texture map statements (`(material, request)`).
pub(super) fn check_mtl(
    path: &Path,
    src: &str,
    warnings: &mut Vec<String>,
    maps: &mut Vec<(String, MapRequest)>,
) -> Result<(), Error> {
    let c = Checker { path, src };
    let mut unused: Vec<&str> = Vec::new();
    let mut current = String::new();
    for (start, line) in lines(src) {
        let content = line.split('#').next().unwrap_or("");
        let mut it = content.split_whitespace();
        let Some(kw) = it.next() else { continue };
        let rest: Vec<&str> = it.collect();
        if kw == "newmtl" {
            current = rest.join(" ");
        }
        let is_map = kw.starts_with("map_") || matches!(kw, "bump" | "norm" | "disp" | "decal" | "refl");
        if is_map {
            let (l, _) = crate::error::line_col(src, start);
            match parse_mtl_map(kw, &rest) {
                Ok(Some((mut request, options))) => {
                    request.at = format!("{}:{l}", path.display());
                    for o in options {
                        warnings.push(format!("{}: {kw} option {o} is not used", request.at));
                    }
                    maps.push((current.clone(), request));
                }
                Ok(None) => {
                    if !unused.contains(&kw) {
                        unused.push(kw);
                    }
                }
                Err(why) => warnings.push(format!("{}:{l}: {kw} {why}: not used", path.display())),
            }
        }
        let num = |i: usize| -> Result<f32, Error> {
            let f = rest
                .get(i)
                .ok_or_else(|| c.err(start, line, 0, kw, "is missing a number".into()))?;
            f.parse::<f32>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| c.err(start, line, i + 1, kw, format!("{f:?} is not a finite number")))
        };
        match kw {
            "Ka" | "Kd" | "Ks" | "Ke" => {
                if rest.first() == Some(&"spectral") || rest.first() == Some(&"xyz") {
                    return Err(c.err(start, line, 1, kw, "only RGB colours are supported".into()));
                }
                for i in 0..3 {
                    // "Kd r" alone means r = g = b.
                    if i > 0 && rest.len() == 1 {
                        break;
                    }
                    let x = num(i)?;
                    if x < 0.0 {
                        return Err(c.err(start, line, i + 1, kw, format!("must be >= 0, got {x}")));
                    }
                }
            }
            "Ns" => {
                let x = num(0)?;
                if x < 0.0 {
                    return Err(c.err(start, line, 1, kw, format!("shininess must be >= 0, got {x}")));
                }
            }
            "d" | "Tr" => {
                let x = num(0)?;
                if !(0.0..=1.0).contains(&x) {
                    return Err(c.err(start, line, 1, kw, format!("must be in [0, 1], got {x}")));
                }
            }
            "Ni" => {
                if let Err(e) = num(0) {
                    warnings.push(format!("{e}: the optical density is not used; ignored"));
                }
            }
            "illum" => {
                let x = num(0)?;
                if x != x.trunc() || x < 0.0 {
                    return Err(c.err(start, line, 1, kw, format!("must be an integer >= 0, got {x}")));
                }
                if x > 2.0 {
                    let (l, _) = crate::error::line_col(src, start);
                    warnings.push(format!(
                        "{}:{l}: illum {x} is not supported; rendered as illum 2 (Blinn-Phong)",
                        path.display()
                    ));
                }
            }
            _ => {}
        }
    }
    if !unused.is_empty() {
        warnings.push(format!(
            "{}: texture statements not used: {}",
            path.display(),
            unused.join(", ")
        ));
    }
    Ok(())
}

/// The `Tr` of a material that has no `d`: its transparency, as tinyobjloader reads it.
pub(super) fn transparency(m: &tobj::Material) -> Option<f32> {
    if m.dissolve.is_some() {
        return None;
    }
    m.unknown_param.get("Tr").and_then(|t| t.trim().parse::<f32>().ok())
}

/// An MTL material as phong's; `tr_is_opacity` reads `Tr` as the opacity (some exporters
/// write it so). `Ns 0` (or no `Ns`) with `Ks` above 0 is read as no highlight, as Blender
/// reads it (its `(x⁺)⁰` would light every lit point fully): the second value says so.
pub(super) fn to_material(m: &tobj::Material, tr_is_opacity: bool) -> (Material, bool) {
    let def = Material::default();
    let c = |v: Option<[f32; 3]>, d: Color| v.map(Color::from_array).unwrap_or(d);
    let kd = c(m.diffuse, def.diffuse());
    let (ka, ks, ke) = (
        c(m.ambient, def.ambient()),
        c(m.specular, def.specular()),
        c(m.emissive, Color::BLACK),
    );
    let ns = m.shininess.unwrap_or(0.0);
    let no_highlight = ns == 0.0 && ks.to_array().iter().any(|&x| x > 0.0);
    let ks = if no_highlight { Color::BLACK } else { ks };
    let built = match m.illumination_model.unwrap_or(2) {
        0 => Material::new(Color::BLACK, Color::BLACK, Color::BLACK, kd, 0.0),
        1 => Material::new(ka, kd, Color::BLACK, ke, ns),
        _ => Material::new(ka, kd, ks, ke, ns),
    };
    // Values were checked line by line before tobj parsed them.
    let built = built.unwrap_or_default();
    // `d` is the opacity; `Tr`, where there is no `d`, its complement (tinyobjloader's
    // reading), or the opacity itself where the model would otherwise vanish.
    let tr = transparency(m).map(|t| if tr_is_opacity { t } else { 1.0 - t });
    let material = built
        .with_alpha(m.dissolve.or(tr).unwrap_or(1.0).clamp(0.0, 1.0))
        .unwrap_or(built);
    (material, no_highlight && m.illumination_model.unwrap_or(2) >= 2)
}
