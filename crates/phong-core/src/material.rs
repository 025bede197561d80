//! Materials: the surface's side of the Phong model.
//!
//! A material is the five parameters of seed 000 slide 95 and OpenGL's
//! `glMaterial`: ambient `a_m`, diffuse `d_m`, specular `s_m`, emission `e_m`
//! colours and the shininess (specular exponent) `s`, plus an alpha.
//!
//! The 29 classic OpenGL materials ([`Material::named`]) come from
//! `data/materials.tsv`, cross-checked against Kilgard's `teapots.c` and the
//! McReynolds & Blythe SIGGRAPH '97 course table. Their shininess is on
//! OpenGL's 0..128 scale (the published tables give it as a fraction of 128).
//! Seed 000's copy of that table is an OCR-garbled subset and is not used.

use crate::{Color, Error};
use std::sync::LazyLock;

/// A Phong material: `c = e_m + a_m⊗a + Σ d_m⊗d·(N·L) + s_m⊗s·spec^shininess`.
///
/// Built only through validating constructors, so every `Material` has
/// finite, non-negative colours, a finite shininess `>= 0` and an alpha in
/// `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    ambient: Color,
    diffuse: Color,
    specular: Color,
    emission: Color,
    shininess: f32,
    alpha: f32,
}

impl Default for Material {
    /// OpenGL's default material (OpenGL 2.1 spec, table 2.11): ambient 0.2,
    /// diffuse 0.8, specular 0, emission 0, shininess 0, alpha 1.
    fn default() -> Self {
        Material {
            ambient: Color::splat(0.2),
            diffuse: Color::splat(0.8),
            specular: Color::BLACK,
            emission: Color::BLACK,
            shininess: 0.0,
            alpha: 1.0,
        }
    }
}

impl Material {
    /// The full form, as `glMaterial`: every colour and the shininess given.
    /// Alpha is 1; see [`Material::with_alpha`].
    pub fn new(
        ambient: Color,
        diffuse: Color,
        specular: Color,
        emission: Color,
        shininess: f32,
    ) -> Result<Self, Error> {
        check_color("material ambient", ambient)?;
        check_color("material diffuse", diffuse)?;
        check_color("material specular", specular)?;
        check_color("material emission", emission)?;
        check_shininess(shininess)?;
        Ok(Material {
            ambient,
            diffuse,
            specular,
            emission,
            shininess,
            alpha: 1.0,
        })
    }

    /// The "paint" form of seed 001: ambient = diffuse = `paint`, specular
    /// white, no emission.
    pub fn paint(paint: Color, shininess: f32) -> Result<Self, Error> {
        Material::new(paint, paint, Color::WHITE, Color::BLACK, shininess)
    }

    /// The same material with alpha `a` in `[0, 1]` (carried, not used by the
    /// lighting equation; OpenGL takes the fragment's alpha from `d_m`).
    pub fn with_alpha(mut self, a: f32) -> Result<Self, Error> {
        if !(0.0..=1.0).contains(&a) {
            return Err(Error::OutOfRange {
                what: "alpha",
                range: "in [0, 1]",
                value: a,
            });
        }
        self.alpha = a;
        Ok(self)
    }

    /// One of the 29 classic OpenGL materials, by name; case, spaces, `-`
    /// and `_` are ignored (`"Polished Bronze"` = `polished_bronze`).
    /// An unknown name gives [`Error::UnknownMaterial`] with the nearest names.
    pub fn named(name: &str) -> Result<Self, Error> {
        let key = normalize_name(name);
        NAMED
            .iter()
            .find(|m| normalize_name(m.name) == key)
            .map(|m| m.material)
            .ok_or_else(|| Error::UnknownMaterial {
                name: name.to_string(),
                suggestions: nearest_names(name, NAMED.iter().map(|m| m.name)),
            })
    }

    /// Ambient reflectance `a_m`.
    pub fn ambient(&self) -> Color {
        self.ambient
    }
    /// Diffuse reflectance `d_m` (the "base" or "paint" colour).
    pub fn diffuse(&self) -> Color {
        self.diffuse
    }
    /// Specular reflectance `s_m` (colour of the highlights).
    pub fn specular(&self) -> Color {
        self.specular
    }
    /// Emission `e_m`.
    pub fn emission(&self) -> Color {
        self.emission
    }
    /// Specular exponent `s >= 0`.
    pub fn shininess(&self) -> f32 {
        self.shininess
    }
    /// Alpha in `[0, 1]`.
    pub fn alpha(&self) -> f32 {
        self.alpha
    }
}

fn check_color(what: &'static str, c: Color) -> Result<(), Error> {
    if c.is_finite_non_negative() {
        Ok(())
    } else {
        Err(Error::InvalidColor {
            what,
            value: c.to_array(),
        })
    }
}

fn check_shininess(s: f32) -> Result<(), Error> {
    if s.is_finite() && s >= 0.0 {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            what: "shininess",
            range: "finite and >= 0",
            value: s,
        })
    }
}

/// A built-in material and its canonical name (`snake_case`, as in the table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NamedMaterial {
    /// Canonical name, e.g. `"polished_bronze"`.
    pub name: &'static str,
    /// Its values.
    pub material: Material,
}

/// All 29 classic OpenGL materials, in the table's order.
pub fn named_materials() -> &'static [NamedMaterial] {
    &NAMED
}

const MATERIALS_TSV: &str = include_str!("../data/materials.tsv");

static NAMED: LazyLock<Vec<NamedMaterial>> = LazyLock::new(|| parse_table(MATERIALS_TSV));

/// Parses the embedded table. It is a compile-time constant checked by the
/// tests, so a malformed row is a bug in this crate, not user input.
fn parse_table(tsv: &'static str) -> Vec<NamedMaterial> {
    tsv.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let mut cols = line.split('\t');
            let name = cols.next().expect("materials.tsv: name column");
            let v: Vec<f32> = cols.map(|c| c.trim().parse().expect("materials.tsv: number")).collect();
            assert_eq!(v.len(), 11, "materials.tsv: 11 numbers per row");
            let c = |i: usize| Color::new(v[i], v[i + 1], v[i + 2]);
            let material = Material::new(c(0), c(3), c(6), Color::BLACK, v[10])
                .and_then(|m| m.with_alpha(v[9]))
                .expect("materials.tsv: valid material");
            NamedMaterial { name, material }
        })
        .collect()
}

/// A name as looked up: lower case without spaces, `-` or `_` (`"Polished Bronze"` →
/// `"polishedbronze"`).
pub fn normalize_name(s: &str) -> String {
    s.chars()
        .filter(|c| !matches!(c, ' ' | '-' | '_'))
        .flat_map(char::to_lowercase)
        .collect()
}

/// The names closest to `query` (edit distance on normalised names, or
/// containing it), best first, at most three.
pub fn nearest_names<'a>(query: &str, names: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let q = normalize_name(query);
    let mut scored: Vec<(usize, &str)> = names
        .filter_map(|n| {
            let k = normalize_name(n);
            let d = levenshtein(&q, &k);
            let close = d <= (k.len().max(q.len()) / 3).max(2);
            let contains = q.len() >= 3 && (k.contains(&q) || q.contains(&k));
            (close || contains).then_some((if close { d } else { d + 100 }, n))
        })
        .collect();
    scored.sort();
    scored.into_iter().take(3).map(|(_, n)| n).collect()
}

fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_opengl_default() {
        let m = Material::default();
        assert_eq!(m.ambient(), Color::splat(0.2));
        assert_eq!(m.diffuse(), Color::splat(0.8));
        assert_eq!(m.specular(), Color::BLACK);
        assert_eq!(m.emission(), Color::BLACK);
        assert_eq!(m.shininess(), 0.0);
        assert_eq!(m.alpha(), 1.0);
    }

    #[test]
    fn paint_form_of_seed_001() {
        let m = Material::paint(Color::new(0.8, 0.5, 0.3), 8.0).unwrap();
        assert_eq!(m.ambient(), m.diffuse());
        assert_eq!(m.specular(), Color::WHITE);
        assert_eq!(m.shininess(), 8.0);
    }

    #[test]
    fn rejects_negative_and_nan() {
        let ok = Color::splat(0.5);
        assert!(matches!(
            Material::new(ok, Color::new(-0.1, 0.0, 0.0), ok, ok, 1.0),
            Err(Error::InvalidColor {
                what: "material diffuse",
                ..
            })
        ));
        assert!(Material::new(ok, ok, ok, ok, -1.0).is_err());
        assert!(Material::new(ok, ok, ok, ok, f32::NAN).is_err());
        assert!(Material::new(ok, ok, ok, ok, f32::INFINITY).is_err());
        assert!(Material::new(ok, ok, Color::new(0.0, f32::NAN, 0.0), ok, 1.0).is_err());
        assert!(Material::default().with_alpha(1.5).is_err());
        assert!(Material::default().with_alpha(f32::NAN).is_err());
    }

    #[test]
    fn all_29_named_materials() {
        assert_eq!(named_materials().len(), 29);
        let names: Vec<_> = named_materials().iter().map(|m| m.name).collect();
        for n in ["brass", "emerald", "polished_silver", "yellow_rubber", "cyan_plastic"] {
            assert!(names.contains(&n), "{n}");
        }
    }

    /// Values checked by hand against Kilgard's teapots.c, where shininess is
    /// given as a fraction of 128: brass 0.21794872·128 = 27.897436,
    /// emerald 0.6·128 = 76.8, black rubber 0.078125·128 = 10.
    #[test]
    fn named_values_match_published_tables() {
        let brass = Material::named("brass").unwrap();
        assert_eq!(brass.ambient(), Color::new(0.329412, 0.223529, 0.027451));
        assert_eq!(brass.diffuse(), Color::new(0.780392, 0.568627, 0.113725));
        assert_eq!(brass.specular(), Color::new(0.992157, 0.941176, 0.807843));
        assert!((brass.shininess() - 0.21794872 * 128.0).abs() < 1e-3);
        let emerald = Material::named("Emerald").unwrap();
        assert_eq!(emerald.diffuse(), Color::new(0.07568, 0.61424, 0.07568));
        assert!((emerald.shininess() - 0.6 * 128.0).abs() < 1e-4);
        assert_eq!(emerald.alpha(), 0.55);
        let rubber = Material::named("black rubber").unwrap();
        assert!((rubber.shininess() - 0.078125 * 128.0).abs() < 1e-4);
        assert_eq!(rubber.emission(), Color::BLACK);
    }

    #[test]
    fn lookup_ignores_case_spaces_dashes() {
        let a = Material::named("polished_bronze").unwrap();
        for n in [
            "Polished Bronze",
            "polished-bronze",
            "POLISHEDBRONZE",
            " polished bronze",
        ] {
            assert_eq!(Material::named(n).unwrap(), a, "{n}");
        }
    }

    #[test]
    fn unknown_name_suggests_nearest() {
        let e = Material::named("emrald").unwrap_err();
        match &e {
            Error::UnknownMaterial { suggestions, .. } => assert_eq!(suggestions[0], "emerald"),
            _ => panic!("{e:?}"),
        }
        assert!(e.to_string().contains("did you mean emerald"), "{e}");
        let e = Material::named("bronz").unwrap_err();
        assert!(e.to_string().contains("bronze"), "{e}");
        let e = Material::named("zzzzzzzz").unwrap_err();
        assert!(!e.to_string().contains("did you mean"), "{e}");
    }

    /// The embedded copy must equal the project's shared table when it is
    /// present beside the repository (it is in CI).
    #[test]
    fn embedded_table_matches_shared_copy() {
        let shared = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/materials.tsv");
        match std::fs::read_to_string(shared) {
            Ok(s) => assert_eq!(s, MATERIALS_TSV),
            Err(e) => eprintln!("skipped: {shared}: {e}"),
        }
    }
}
