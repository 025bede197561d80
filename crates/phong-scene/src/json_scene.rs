//! Scenes as JSON, with the TOML file's schema: the JSON is written out as TOML, one value
//! a line, and read by the TOML reader, so that both take the same keys, defaults, checks
//! and messages. Each line's JSON path is kept, so an error names its key as a path
//! (`light[1].attenuation`) instead of a line and column.

use crate::toml_scene::{MeshLookup, parse_scene_from};
use crate::{Error, Loaded};
use serde_json::Value;
use std::fmt::Write;
use std::path::Path;

/// An error in a JSON scene: the key's path (`object[0].material`, empty for the whole
/// scene) and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct JsonError {
    /// The JSON path of the value at fault.
    pub path: String,
    /// What is wrong, as the TOML reader says it.
    pub message: String,
}

impl std::fmt::Display for JsonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.path.is_empty() {
            f.write_str(&self.message)
        } else {
            write!(f, "`{}`: {}", self.path, self.message)
        }
    }
}

impl std::error::Error for JsonError {}

/// A JSON scene as TOML text (what `phong render` reads), with the JSON path of each line
/// (`paths[0]` is line 1).
pub struct TomlText {
    /// The TOML file.
    pub text: String,
    /// The JSON path each line holds.
    pub paths: Vec<String>,
}

/// Writes `scene` (a JSON object with the scene file's sections) as a TOML scene file.
pub fn json_to_toml(scene: &Value) -> Result<TomlText, JsonError> {
    let Value::Object(root) = scene else {
        return Err(JsonError {
            path: String::new(),
            message: "a scene is a JSON object ({\"image\": {...}, \"light\": [...], ...})".into(),
        });
    };
    let mut out = TomlText {
        text: String::new(),
        paths: Vec::new(),
    };
    let mut line = |out: &mut TomlText, text: String, path: String| {
        out.text.push_str(&text);
        out.text.push('\n');
        out.paths.push(path);
    };
    // Plain values first (TOML's root table), then tables, then arrays of tables.
    for (k, v) in root {
        if !is_table(v) && !is_table_array(v) {
            line(&mut out, format!("{} = {}", key(k), inline(v, k)?), k.clone());
        }
    }
    for (k, v) in root {
        if let Value::Object(t) = v {
            table(&mut out, &mut line, &key(k), k, t)?;
        }
    }
    for (k, v) in root {
        if let (true, Value::Array(items)) = (is_table_array(v), v) {
            for (i, item) in items.iter().enumerate() {
                let path = format!("{k}[{i}]");
                line(&mut out, format!("[[{}]]", key(k)), path.clone());
                if let Value::Object(t) = item {
                    for (ik, iv) in t {
                        let p = format!("{path}.{ik}");
                        line(&mut out, format!("{} = {}", key(ik), inline(iv, &p)?), p.clone());
                    }
                }
            }
        }
    }
    Ok(out)
}

/// A `[header]` table: its plain values, then its sub-tables (`[materials.gold]`).
fn table(
    out: &mut TomlText,
    line: &mut impl FnMut(&mut TomlText, String, String),
    header: &str,
    path: &str,
    t: &serde_json::Map<String, Value>,
) -> Result<(), JsonError> {
    line(out, format!("[{header}]"), path.to_string());
    for (k, v) in t {
        if !is_table(v) {
            let p = format!("{path}.{k}");
            line(out, format!("{} = {}", key(k), inline(v, &p)?), p.clone());
        }
    }
    for (k, v) in t {
        if let Value::Object(sub) = v {
            table(out, line, &format!("{header}.{}", key(k)), &format!("{path}.{k}"), sub)?;
        }
    }
    Ok(())
}

fn is_table(v: &Value) -> bool {
    matches!(v, Value::Object(_))
}

fn is_table_array(v: &Value) -> bool {
    matches!(v, Value::Array(a) if !a.is_empty() && a.iter().all(is_table))
}

/// A key, bare where TOML allows it, else quoted.
fn key(k: &str) -> String {
    let bare = !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare { k.to_string() } else { string(k) }
}

/// A TOML basic string on one line, whatever `s` holds (a multi-line string would break the
/// one-value-a-line map of paths, and is not allowed as a key).
fn string(s: &str) -> String {
    let mut o = String::with_capacity(s.len() + 2);
    o.push('"');
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            '\n' => o.push_str("\\n"),
            '\r' => o.push_str("\\r"),
            '\t' => o.push_str("\\t"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => {
                let _ = write!(o, "\\u{:04X}", c as u32);
            }
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

/// A value on one line: numbers, strings, booleans, arrays and inline tables.
fn inline(v: &Value, path: &str) -> Result<String, JsonError> {
    let err = |message: &str| JsonError {
        path: path.to_string(),
        message: message.to_string(),
    };
    Ok(match v {
        Value::Null => return Err(err("null is not a value: leave the key out for its default")),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => i.to_string(),
            (None, Some(f)) if n.is_f64() => toml::Value::Float(f).to_string(),
            _ => return Err(err("the number is out of range")),
        },
        Value::String(s) => string(s),
        Value::Array(items) => {
            let mut s = String::from("[");
            for (i, item) in items.iter().enumerate() {
                if i > 0 {
                    s.push_str(", ");
                }
                s.push_str(&inline(item, &format!("{path}[{i}]"))?);
            }
            s.push(']');
            s
        }
        Value::Object(t) => {
            let mut s = String::from("{");
            for (i, (k, item)) in t.iter().enumerate() {
                let _ = write!(
                    s,
                    "{}{} = {}",
                    if i > 0 { ", " } else { " " },
                    key(k),
                    inline(item, &format!("{path}.{k}"))?
                );
            }
            s.push_str(if t.is_empty() { "}" } else { " }" });
            s
        }
    })
}

/// Reads a JSON scene as the TOML reader reads the same scene's file, with meshes from
/// `meshes` (never from the file system).
pub fn parse_scene_json(scene: &Value, meshes: &MeshLookup) -> Result<Loaded, JsonError> {
    parse_json_with(scene, Path::new("scene.json"), Some(meshes), false)
}

/// [`parse_scene_json`] as if the scene were the file `anchor`: its mesh and texture paths
/// relative to `anchor`'s folder, its meshes from `meshes` where given, else read from there,
/// its textures read from there.
pub fn parse_scene_json_at(scene: &Value, anchor: &Path, meshes: Option<&MeshLookup>) -> Result<Loaded, JsonError> {
    parse_json_with(scene, anchor, meshes, true)
}

fn parse_json_with(
    scene: &Value,
    anchor: &Path,
    meshes: Option<&MeshLookup>,
    files: bool,
) -> Result<Loaded, JsonError> {
    let toml = json_to_toml(scene)?;
    parse_scene_from(&toml.text, anchor, meshes, files).map_err(|e| match e {
        Error::Parse { line, key, message, .. } => {
            let at = toml.paths.get(line.wrapping_sub(1)).cloned().unwrap_or_default();
            let path = match key {
                None => at,
                Some(k) if at.is_empty() => k,
                Some(k) if element_name(&at) == k => at,
                Some(k) => format!("{at}.{k}"),
            };
            JsonError { path, message }
        }
        other => JsonError {
            path: String::new(),
            message: other.to_string(),
        },
    })
}

/// A TOML scene file's text as the JSON value of the same scene (what [`parse_scene_json`]
/// reads), an error at its line and column where it is not TOML.
pub fn toml_to_json(src: &str, path: &Path) -> Result<Value, Error> {
    let value: toml::Value = toml::from_str(&crate::toml_scene::quiet_blank_lines(src)).map_err(|e| {
        let offset = e.span().map_or(0, |s| s.start);
        Error::at(path, src, offset, None, e.message().trim().to_string())
    })?;
    serde_json::to_value(value).map_err(|e| Error::at(path, src, 0, None, e.to_string()))
}

/// The name of a path's last element: `attenuation` of `light[1].attenuation`, `light` of
/// `light[1]`.
fn element_name(path: &str) -> &str {
    let base = path.split('[').next().unwrap_or(path);
    let last = path.rsplit('.').next().unwrap_or(path);
    if last.contains('[') {
        base.rsplit('.').next().unwrap_or(base)
    } else {
        last
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn no_meshes(name: &str) -> Result<Vec<crate::ModelPart>, String> {
        Err(format!("no uploaded model named \"{name}\""))
    }

    fn err(v: Value) -> JsonError {
        parse_scene_json(&v, &no_meshes).expect_err("an invalid scene")
    }

    #[test]
    fn same_scene_as_the_toml_file() {
        let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/scenes/tour.toml"))
            .expect("tour.toml");
        let value: toml::Value = toml::from_str(&src).expect("toml");
        let json = serde_json::to_value(&value).expect("json");
        let from_json = parse_scene_json(&json, &no_meshes)
            .expect("the tour scene as JSON")
            .scene;
        let from_toml = crate::parse_scene(&src, Path::new("tour.toml"))
            .expect("tour.toml")
            .scene;
        assert_eq!(format!("{from_json:?}"), format!("{from_toml:?}"));
    }

    #[test]
    fn errors_name_the_json_path() {
        let light = |att: Value| {
            json!({"light": [
                {"type": "directional", "direction": [0, -1, 0]},
                {"type": "point", "position": [0, 1, 0], "attenuation": att},
            ]})
        };
        let e = err(light(json!([0, 1, 0])));
        assert_eq!(e.path, "light[1].attenuation");
        assert!(e.message.contains("constant"), "{e}");
        let e = err(light(json!([1, 0])));
        assert_eq!(e.path, "light[1].attenuation");
        let e = err(json!({"light": [{"type": "point"}]}));
        assert_eq!(
            (e.path.as_str(), e.message.as_str()),
            ("light[0].position", "a point light needs `position`")
        );
        let e = err(json!({"image": {"widht": 3}}));
        assert_eq!(e.path, "image.widht");
        assert!(e.message.contains("unknown field `widht`"), "{e}");
        let e = err(json!({"image": {"width": 0}}));
        assert_eq!(
            (e.path.as_str(), e.message.as_str()),
            ("image.width", "must be from 1 to 16384, got 0")
        );
        let e = err(json!({"object": [{"shape": "sphere"}, {"shape": "sphear"}]}));
        assert_eq!(e.path, "object[1].shape");
        assert!(e.message.contains("did you mean \"sphere\""), "{e}");
        let e = err(json!({"object": [{"shape": "sphere", "material": {"shininess": -1}}]}));
        assert_eq!(
            (e.path.as_str(), e.message.as_str()),
            ("object[0].material.shininess", "must be >= 0, got -1")
        );
        let e = err(json!({"materials": {"my gold": {"base": "gold", "shininess": -2}}}));
        assert_eq!(e.path, "materials.my gold.shininess");
        let e = err(json!({"camera": {"fov": null}}));
        assert_eq!(e.path, "camera.fov");
        let e = err(json!([1, 2]));
        assert_eq!(e.path, "");
    }

    #[test]
    fn meshes_come_from_the_lookup_not_the_disk() {
        // A file that exists on disk is still refused: only the lookup is asked.
        let e = err(json!({"object": [{"mesh": "Cargo.toml"}]}));
        assert_eq!(e.path, "object[0].mesh");
        assert_eq!(e.message, "no uploaded model named \"Cargo.toml\"");
    }

    #[test]
    fn strings_with_newlines_stay_on_their_line() {
        // Found by the scene_json fuzz target: a key with a newline was written as a multi-line
        // string, which TOML refuses for keys, and which moved every later line's path.
        let e = err(json!({"image": {"\nwidth": 4}}));
        assert_eq!(e.path, "image.\nwidth");
        assert!(e.message.contains("unknown field"), "{e}");
        let e = err(json!({"object": [{"shape": "sph\nere\t\"\\\u{1}"}], "light": [{"type": "point"}]}));
        assert_eq!(e.path, "light[0].position");
        let e = err(json!({"object": [{"shape": "sph\nere"}]}));
        assert_eq!(e.path, "object[0].shape");
        let t = json_to_toml(&json!({"a\"b": "x\ny", "c": {"d\re": 1}})).expect("toml");
        assert!(t.text.parse::<toml::Table>().is_ok(), "{}", t.text);
        assert_eq!(t.text.lines().count(), t.paths.len());
    }

    #[test]
    fn toml_text_renders_the_same_scene() {
        let v = json!({"image": {"width": 64, "height": 48, "background": [0.1, 0.2, 0.3]},
            "shading": {"model": "phong"},
            "light": [{"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0], "cutoff": 30.5}],
            "object": [{"shape": "teapot", "material": "gold", "rotation": [0, 30, 0]}]});
        let t = json_to_toml(&v).expect("toml");
        let a = crate::parse_scene(&t.text, Path::new("x.toml")).expect("valid").scene;
        let b = parse_scene_json(&v, &no_meshes).expect("valid").scene;
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert_eq!(a.image.width, 64);
        assert_eq!(a.image.background, [0.1, 0.2, 0.3, 1.0]);
    }
}
