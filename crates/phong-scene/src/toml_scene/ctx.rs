//! The reader's context: the file (for errors at a span), its warnings, the files read, the
//! triangle budget, where meshes come from; and the checked readers of numbers, vectors,
//! colours and names.

use super::choices::parse_choice;
pub(crate) use super::raw::S;
use crate::{Error, ModelPart};
use glam::Vec3;
use phong_core::Color;
use std::path::Path;

pub(crate) struct Ctx<'a> {
    pub path: &'a Path,
    pub src: &'a str,
    pub warnings: Vec<String>,
    /// Files read for the scene's meshes (OBJ and MTL).
    pub sources: Vec<std::path::PathBuf>,
    /// Triangles of the objects read so far (the per-scene budget).
    pub triangles: std::cell::Cell<u64>,
    /// Where `mesh = "..."` names come from: `None` reads files beside the scene; `Some`
    /// looks them up in memory (the server's uploads) and never opens a file.
    pub meshes: Option<&'a MeshLookup<'a>>,
    /// Whether texture files may be read (not for a scene sent to `phong serve`).
    pub files: bool,
    /// Texture images read so far (a file named by several materials is read once).
    pub textures: crate::texture_file::TextureCache,
}

/// Resolves a `mesh` name to its parts without touching the file system (the error is the
/// message shown for the `mesh` key).
pub type MeshLookup<'a> = dyn Fn(&str) -> Result<Vec<ModelPart>, String> + 'a;

impl Ctx<'_> {
    /// Counts an object's triangles against the scene's budget.
    pub fn add_triangles(&self, n: u64, span: &std::ops::Range<usize>, key: &str) -> Result<(), Error> {
        self.triangles.set(self.triangles.get().saturating_add(n));
        let max = phong_core::limits::MAX_SCENE_TRIANGLES;
        if self.triangles.get() > max {
            return self.err(
                span,
                key,
                format!(
                    "the scene's objects have {} triangles so far; a scene may have at most {max} (MAX_SCENE_TRIANGLES)",
                    self.triangles.get()
                ),
            );
        }
        Ok(())
    }

    pub fn err<T>(&self, span: &std::ops::Range<usize>, key: &str, msg: impl Into<String>) -> Result<T, Error> {
        Err(Error::at(self.path, self.src, span.start, Some(key), msg.into()))
    }

    pub fn choice<T: Copy>(&self, s: &S<String>, key: &str, table: &[(&str, T)]) -> Result<T, Error> {
        parse_choice(key, s.get_ref(), table).or_else(|m| self.err(&s.span(), key, m))
    }

    pub fn name<'b>(&self, s: &S<String>, key: &str, names: &[&'b str]) -> Result<&'b str, Error> {
        let table: Vec<(&str, &str)> = names.iter().map(|n| (*n, *n)).collect();
        self.choice(s, key, &table)
    }

    pub fn vec3(&self, s: &S<Vec<f32>>, key: &str) -> Result<Vec3, Error> {
        let v = s.get_ref();
        if v.len() != 3 {
            return self.err(&s.span(), key, format!("expected 3 numbers [x, y, z], got {}", v.len()));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return self.err(&s.span(), key, "numbers must be finite");
        }
        Ok(Vec3::new(v[0], v[1], v[2]))
    }

    pub fn color(&self, s: &S<Vec<f32>>, key: &str) -> Result<Color, Error> {
        let v = s.get_ref();
        if v.len() != 3 {
            return self.err(&s.span(), key, format!("expected 3 numbers [r, g, b], got {}", v.len()));
        }
        if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return self.err(&s.span(), key, "colour components must be finite and >= 0");
        }
        Ok(Color::new(v[0], v[1], v[2]))
    }

    pub fn opt_color(&self, s: &Option<S<Vec<f32>>>, key: &str) -> Result<Option<Color>, Error> {
        s.as_ref().map(|s| self.color(s, key)).transpose()
    }

    pub fn num(&self, s: &S<f32>, key: &str, ok: impl Fn(f32) -> bool, range: &str) -> Result<f32, Error> {
        let v = *s.get_ref();
        if v.is_finite() && ok(v) {
            Ok(v)
        } else {
            self.err(&s.span(), key, format!("must be {range}, got {v}"))
        }
    }

    pub fn int(&self, s: &S<i64>, key: &str, lo: i64, hi: i64) -> Result<i64, Error> {
        let v = *s.get_ref();
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            self.err(&s.span(), key, format!("must be from {lo} to {hi}, got {v}"))
        }
    }
}
