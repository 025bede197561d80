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

/// The exponent search shared by both fits: `f(s)` at every point of `grid` (increasing), then
/// golden-section search on `log s` between the best point's neighbours for `iterations`
/// steps; the best value seen and its `s`. `f` returns its solution and its error.
pub(crate) fn search_exponent<T: Copy, E>(
    grid: &[f32],
    iterations: usize,
    mut f: impl FnMut(f32) -> Result<(T, f64), E>,
) -> Result<((T, f64), f32), E> {
    let mut results = Vec::with_capacity(grid.len());
    for &s in grid {
        results.push(f(s)?);
    }
    let best = (0..grid.len())
        .min_by(|&i, &j| results[i].1.total_cmp(&results[j].1))
        .expect("a grid");
    let (mut lo, mut hi) = (
        grid[best.saturating_sub(1)].ln(),
        grid[(best + 1).min(grid.len() - 1)].ln(),
    );
    let phi = 0.618_034_f32;
    let (mut x1, mut x2) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
    let (mut f1, mut f2) = (f(x1.exp())?, f(x2.exp())?);
    for _ in 0..iterations {
        if f1.1 < f2.1 {
            (hi, x2, f2) = (x2, x1, f1);
            x1 = hi - phi * (hi - lo);
            f1 = f(x1.exp())?;
        } else {
            (lo, x1, f1) = (x1, x2, f2);
            x2 = lo + phi * (hi - lo);
            f2 = f(x2.exp())?;
        }
    }
    let mut cands = [(results[best], grid[best]), (f1, x1.exp()), (f2, x2.exp())];
    cands.sort_by(|a, b| a.0.1.total_cmp(&b.0.1));
    Ok(cands[0])
}

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

impl FitError {
    /// Whether the error is in what the user gave.
    pub fn is_input(&self) -> bool {
        matches!(self, FitError::Input(_))
    }
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
