//! The TOML scene format (docs/scenes.md lists every key), a module a section.
//!
//! serde with `deny_unknown_fields` rejects unknown keys and wrong types with the span toml
//! gives (`raw`); values that need checking are read as `Spanned` so that a bad one is
//! reported at its own line and column (`ctx`).

mod camera;
mod choices;
mod ctx;
mod image;
mod light;
mod material;
pub(crate) mod object;
mod raw;
mod shading;

pub use choices::{INTERPOLATIONS, MODELS, Model, OUTPUTS, apply_model, parse_choice};
pub use ctx::MeshLookup;

use crate::overrides::Overrides;
use crate::{Error, Loaded};
use camera::camera;
use ctx::Ctx;
use image::image_settings;
use light::light;
use material::material;
use object::object;
use phong_core::limits::MAX_LIGHTS;
use phong_core::{Color, Label, Light, LightColor, Lighting, Scene, normalize_name};
use raw::RawScene;
use shading::shading;
use std::collections::BTreeMap;
use std::path::Path;

/// Parses a scene file's text; `path` names it in errors and anchors relative mesh paths.
pub fn parse_scene(src: &str, path: &Path) -> Result<Loaded, Error> {
    parse_scene_with(src, path, None)
}

/// [`parse_scene`] with meshes from `meshes` instead of the file system (when given).
pub fn parse_scene_with(src: &str, path: &Path, meshes: Option<&MeshLookup>) -> Result<Loaded, Error> {
    parse_scene_from(src, path, meshes, meshes.is_none())
}

/// [`parse_scene_with`], reading texture files beside `path` where `files` (a scene whose
/// meshes come from a lookup may still name textures: `phong batch`, the Python module), or
/// refusing them (a scene sent to `phong serve`).
pub fn parse_scene_from(src: &str, path: &Path, meshes: Option<&MeshLookup>, files: bool) -> Result<Loaded, Error> {
    let _budget = crate::texture_file::TextureBudget::start();
    let raw: RawScene = toml::from_str(&quiet_blank_lines(src)).map_err(|e| {
        let offset = e.span().map_or(0, |s| s.start);
        // The whole line the error is on (an error at a key's start, as "duplicate key", has
        // nothing before it on the line).
        let offset_c = offset.min(src.len());
        let start = src[..offset_c].rfind('\n').map_or(0, |i| i + 1);
        let end = src[offset_c..].find('\n').map_or(src.len(), |i| offset_c + i);
        let line_text = src.get(start..end).unwrap_or("");
        let line_key = line_text
            .split_once('=')
            .map(|(k, _)| k.trim().to_string())
            .filter(|k| !k.is_empty())
            .map(|k| unquote_key(&k));
        let message = user_words(e.message().trim())
            // serde's words for a value that is none of a key's forms, in the user's words.
            .replace(
                "data did not match any variant of untagged enum MaterialRef",
                "must be a material's name or a table of its keys ({ diffuse = [r, g, b], shininess = s, ... }): \
                 a key of the table is misspelt or holds a value of the wrong kind",
            )
            .replace(
                "data did not match any variant of untagged enum Scale",
                "must be a number (uniform) or [x, y, z]",
            );
        // An error at a key itself ("duplicate key", also inside an inline table) names that
        // key; others the line's.
        let at_key = src
            .get(offset_c..end)
            .and_then(|t| t.split_once('='))
            .map(|(k, _)| k.trim())
            .filter(|k| message.starts_with("duplicate key") && !k.is_empty() && !k.contains([',', '{', '[']))
            .map(unquote_key);
        // Inside an inline material table, the key inside it and what is wrong with it.
        if e.message().contains("untagged enum MaterialRef")
            && let Some((inner_offset, key, inner)) = inline_material_error(src, offset)
        {
            return Error::at(path, src, inner_offset, Some(&key), inner);
        }
        Error::at(path, src, offset, at_key.or(line_key).as_deref(), message)
    })?;
    let mut ctx = Ctx {
        path,
        src,
        warnings: Vec::new(),
        sources: Vec::new(),
        triangles: std::cell::Cell::new(0),
        meshes,
        files,
        textures: Default::default(),
    };
    let scene = build(&mut ctx, raw)?;
    Ok(Loaded {
        scene,
        warnings: ctx.warnings,
        sources: ctx.sources,
        notes: Vec::new(),
        textures: Default::default(),
        times: Default::default(),
    })
}

/// `src` with every run of blank or comment-only lines after a newline turned into spaces,
/// byte for byte (so that every offset, and so every line and column reported, is the file's
/// own): the TOML parser keeps a token or two a line, about 48 bytes each, so a file of 10 MB
/// of newlines or comments took half a gigabyte. A file with multi-line strings (whose blank
/// lines are their text) is left as it is.
pub(crate) fn quiet_blank_lines(src: &str) -> std::borrow::Cow<'_, str> {
    let b = src.as_bytes();
    let lines = b.iter().filter(|&&c| c == b'\n').count();
    if lines < 1024 || src.contains("\"\"\"") || src.contains("\'\'\'") {
        return std::borrow::Cow::Borrowed(src);
    }
    let quiet = |line: &[u8]| {
        let rest: &[u8] = match line.iter().position(|c| !matches!(c, b' ' | b'\t' | b'\r')) {
            None => return true,
            Some(k) => &line[k..],
        };
        rest.first() == Some(&b'#')
    };
    let mut out = b.to_vec();
    let mut i = 0;
    while i < out.len() {
        if out[i] != b'\n' {
            i += 1;
            continue;
        }
        // A newline: the quiet lines after it, newlines and all, become spaces (the first
        // line that says something keeps its own text).
        let (mut j, mut last) = (i + 1, i);
        while let Some(end) = out[j..].iter().position(|&c| c == b'\n').map(|k| j + k) {
            if !quiet(&out[j..end]) {
                break;
            }
            last = end;
            j = end + 1;
        }
        for c in &mut out[i + 1..=last] {
            *c = b' ';
        }
        i = last.max(i) + 1;
    }
    // Whole lines of comments and blanks became spaces: still UTF-8.
    std::borrow::Cow::Owned(String::from_utf8(out).expect("still UTF-8"))
}

/// toml's and serde's messages in the user's words: "invalid type: string \"tall\", expected
/// i64" becomes "must be an integer, got the text \"tall\""; an integer past `i64` says so.
fn user_words(m: &str) -> String {
    let big = m
        .strip_prefix("invalid type: integer `")
        .filter(|r| r.contains("as i128"))
        .or_else(|| m.strip_prefix("invalid value: integer `"))
        .and_then(|r| r.split_once('`'))
        .map(|(n, _)| n)
        .filter(|n| n.parse::<i64>().is_err());
    if let Some(n) = big {
        return format!("{n} is too large: integers here are at most {}", i64::MAX);
    }
    let Some((got, wanted)) = m
        .strip_prefix("invalid type: ")
        .and_then(|r| r.split_once(", expected "))
    else {
        return m.to_string();
    };
    let wanted = match wanted {
        "i64" | "u32" | "u8" | "i32" | "an integer" => "an integer".to_string(),
        "f32" | "f64" => "a number".into(),
        "a sequence" => "a list ([...])".into(),
        "a string" => "text in quotes".into(),
        "a boolean" => "true or false".into(),
        w if w.starts_with("struct ") || w == "a map" => "a table ({ ... } or [section])".into(),
        w => w.to_string(),
    };
    let got = if let Some(t) = got.strip_prefix("string ") {
        format!("the text {t}")
    } else if let Some(v) = ["floating point ", "integer ", "boolean "]
        .iter()
        .find_map(|p| got.strip_prefix(p))
    {
        v.trim_matches('`').to_string()
    } else {
        match got {
            "sequence" => "a list".to_string(),
            "map" => "a table".to_string(),
            other => other.to_string(),
        }
    };
    format!("must be {wanted}, got {got}")
}

/// The error inside an inline material table `{ ... }` whose value starts at `offset`: the
/// offset of the faulty key in `src`, the key, and the message (the table read alone as a
/// material's keys).
fn inline_material_error(src: &str, offset: usize) -> Option<(usize, String, String)> {
    let rest = src.get(offset..)?;
    if !rest.starts_with('{') {
        return None;
    }
    let text = &rest[..rest.find('\n').unwrap_or(rest.len())];
    let table: toml::Table = toml::from_str(&format!("t = {text}")).ok()?;
    let inner = table.get("t")?.as_table()?;
    // The table as a document of its own: one key a line, each error located there.
    let doc = toml::to_string(inner).ok()?;
    let e = match toml::from_str::<raw::PlainMaterial>(&doc) {
        Ok(_) => return None,
        Err(e) => e,
    };
    let at = e.span().map_or(0, |s| s.start);
    let line_start = doc[..at.min(doc.len())].rfind('\n').map_or(0, |i| i + 1);
    let key = doc[line_start..].split_once('=').map(|(k, _)| unquote_key(k.trim()))?;
    // The key's place in the original line.
    let key_offset = text.find(&key).map_or(offset, |i| offset + i);
    Some((key_offset, key, user_words(e.message().trim())))
}

/// A quoted key (`"my key"`) as the key itself; a bare key as it is.
fn unquote_key(k: &str) -> String {
    if (k.starts_with('"') || k.starts_with('\''))
        && let Ok(t) = toml::from_str::<toml::Table>(&format!("{k} = 0"))
        && let Some(name) = t.keys().next()
    {
        return name.clone();
    }
    k.to_string()
}

fn build(ctx: &mut Ctx, raw: RawScene) -> Result<Scene, Error> {
    let image = image_settings(ctx, raw.image.unwrap_or_default())?;
    let camera = camera(ctx, raw.camera.unwrap_or_default())?;
    let shading = shading(ctx, raw.shading.as_ref(), &camera)?;
    let ambient = match raw.shading.as_ref().and_then(|s| s.ambient.as_ref()) {
        Some(a) => ctx.color(a, "ambient")?,
        None => Color::splat(0.2),
    };
    if raw.light.len() > MAX_LIGHTS {
        return ctx.err(
            &raw.light[MAX_LIGHTS].span(),
            "light",
            format!("at most {MAX_LIGHTS} lights"),
        );
    }
    let mut lights = Vec::new();
    for l in &raw.light {
        lights.push(light(ctx, l)?);
    }
    if raw.light.is_empty() {
        // OpenGL's light 0 in eye space, (0, 0, 1, 0): white, from the camera.
        lights.push(Light::directional(camera.forward(), LightColor::default()).expect("unit direction"));
    }
    let lighting = Lighting::new(ambient, lights).expect("checked colour");
    let mut named = BTreeMap::new();
    for (name, m) in &raw.materials {
        let key = format!("materials.{name}");
        let mat = material(ctx, m.get_ref(), &key, &named)?;
        named.insert(normalize_name(name), mat);
    }
    let mut objects = Vec::new();
    for o in &raw.object {
        let r = o.get_ref();
        let overrides = Overrides {
            model: r.model.as_ref().map(|m| ctx.choice(m, "model", MODELS)).transpose()?,
            interpolation: (r.interpolation.as_ref())
                .map(|i| ctx.choice(i, "interpolation", INTERPOLATIONS))
                .transpose()?,
            output: r
                .output
                .as_ref()
                .map(|o| ctx.choice(o, "output", OUTPUTS))
                .transpose()?,
        };
        let mut sh = shading;
        overrides.apply(&mut sh);
        objects.extend(object(ctx, o, &named, sh)?);
    }
    let mut labels = Vec::new();
    for l in &raw.label {
        let l = l.get_ref();
        let size = match &l.size {
            Some(sz) => ctx.int(sz, "size", 1, 64)? as u32,
            None => 2,
        };
        labels.push(Label {
            text: l.text.get_ref().clone(),
            position: ctx.vec3(&l.position, "position")?,
            color: ctx.opt_color(&l.color, "color")?.unwrap_or(Color::WHITE),
            size,
        });
    }
    Ok(Scene {
        image,
        camera,
        lighting,
        objects,
        labels,
    })
}

#[cfg(test)]
mod quiet_tests {
    use super::quiet_blank_lines;

    #[test]
    fn blank_and_comment_lines_become_spaces_offsets_kept() {
        let filler = "\n  \n# a comment, é\n\t\n".repeat(400);
        let src = format!("a = 1\n{filler}b = [\n1,\n{filler}2]\n");
        let q = quiet_blank_lines(&src);
        assert_eq!(q.len(), src.len(), "byte for byte");
        assert_eq!(q.find("b = ["), src.find("b = ["));
        assert!(!q.contains('#'));
        let t: toml::Table = toml::from_str(&q).expect("still TOML");
        assert_eq!(t["a"].as_integer(), Some(1));
        assert_eq!(t["b"].as_array().map(Vec::len), Some(2));
        // Multi-line strings keep their blank lines: the text is left as it is.
        let s = format!("s = \"\"\"\n{filler}\"\"\"\n");
        assert_eq!(quiet_blank_lines(&s), s);
        // Small files are not touched.
        assert!(matches!(
            quiet_blank_lines("a = 1\n\n\nb = 2\n"),
            std::borrow::Cow::Borrowed(_)
        ));
    }
}
