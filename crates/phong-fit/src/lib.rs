//! # phong-fit
//!
//! `phong fit`: the Phong material that best matches a target image of a known scene
//! ([`image`]), or a physically based or measured BRDF ([`brdf`]). Both are variable
//! projection: for a fixed exponent the colours are a box-constrained linear least-squares
//! solve ([`lsq`]), exact; the exponent alone is searched. [`report`] writes the pictures.

// Index loops over channels and unknowns read as the sums of the normal equations they compute.
#![allow(clippy::needless_range_loop)]

pub mod brdf;
pub mod image;
pub mod lsq;
pub mod report;

use phong_core::Material;

/// Why a fit could not be made.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// Something the user gave (exit code 2).
    #[error("{0}")]
    Input(String),
    /// The renderer failed.
    #[error("rendering failed: {0}")]
    Render(String),
}

fn num(x: f32) -> String {
    let r = (f64::from(x) * 1e6).round() / 1e6;
    format!("{r}")
}

fn rgb(c: phong_core::Color) -> String {
    format!("[{}, {}, {}]", num(c.r), num(c.g), num(c.b))
}

/// The material as a scene file's `[materials.NAME]` block.
pub fn toml_block(name: &str, m: &Material) -> String {
    format!(
        "[materials.{name}]\nambient = {}\ndiffuse = {}\nspecular = {}\nemission = {}\nshininess = {}\n",
        rgb(m.ambient()),
        rgb(m.diffuse()),
        rgb(m.specular()),
        rgb(m.emission()),
        num(m.shininess())
    )
}

/// The material as an MTL entry (`illum 2`: Blinn-Phong in phong's OBJ reader).
pub fn mtl_entry(name: &str, m: &Material) -> String {
    let c = |c: phong_core::Color| format!("{} {} {}", num(c.r), num(c.g), num(c.b));
    format!(
        "newmtl {name}\nKa {}\nKd {}\nKs {}\nKe {}\nNs {}\nillum 2\n",
        c(m.ambient()),
        c(m.diffuse()),
        c(m.specular()),
        c(m.emission()),
        num(m.shininess())
    )
}
