//! Lights: directional, point and spot, as OpenGL's fixed-function lights.
//!
//! A light has three colours, ambient `a_l`, diffuse `d_l` (Wikipedia's
//! `i_d`) and specular `s_l` (`i_s`). [`LightColor::uniform`] gives the usual
//! single-colour light of seed 001 (diffuse = specular = colour, no ambient:
//! the scene's global ambient light carries the ambient term), which is also
//! OpenGL's default for light 0.
//!
//! Positional lights are attenuated by `1/(k0 + k1·d + k2·d²)` and spot
//! lights by `max(−L·ŝ, 0)^exponent` inside the cutoff cone, 0 outside
//! (OpenGL 2.1 spec §2.14.1). Both factors scale all three terms of the light,
//! the ambient one included, as OpenGL does.

use crate::{Color, Error};
use glam::Vec3;

/// The three colours of a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightColor {
    ambient: Color,
    diffuse: Color,
    specular: Color,
}

impl LightColor {
    /// One colour `c`: diffuse = specular = `c`, ambient black.
    pub fn uniform(c: Color) -> Result<Self, Error> {
        LightColor::new(Color::BLACK, c, c)
    }

    /// Separate ambient, diffuse and specular colours (OpenGL's
    /// `GL_AMBIENT`, `GL_DIFFUSE`, `GL_SPECULAR` of a light).
    pub fn new(ambient: Color, diffuse: Color, specular: Color) -> Result<Self, Error> {
        for (what, c) in [
            ("light ambient", ambient),
            ("light diffuse", diffuse),
            ("light specular", specular),
        ] {
            if !c.is_finite_non_negative() {
                return Err(Error::InvalidColor {
                    what,
                    value: c.to_array(),
                });
            }
        }
        Ok(LightColor {
            ambient,
            diffuse,
            specular,
        })
    }

    /// Ambient colour `a_l`.
    pub fn ambient(&self) -> Color {
        self.ambient
    }
    /// Diffuse colour `d_l`.
    pub fn diffuse(&self) -> Color {
        self.diffuse
    }
    /// Specular colour `s_l`.
    pub fn specular(&self) -> Color {
        self.specular
    }
}

impl Default for LightColor {
    /// White diffuse and specular, no ambient.
    fn default() -> Self {
        LightColor {
            ambient: Color::BLACK,
            diffuse: Color::WHITE,
            specular: Color::WHITE,
        }
    }
}

/// Distance attenuation `1 / (k0 + k1·d + k2·d²)`.
///
/// Valid only when the denominator can never reach 0 for `d >= 0`:
/// `k0 > 0`, `k1 >= 0`, `k2 >= 0`, all finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation {
    k: [f32; 3],
}

impl Attenuation {
    /// No attenuation, `(1, 0, 0)` (OpenGL's default).
    pub const NONE: Attenuation = Attenuation { k: [1.0, 0.0, 0.0] };

    /// Constant `k0`, linear `k1` and quadratic `k2` coefficients.
    pub fn new(k0: f32, k1: f32, k2: f32) -> Result<Self, Error> {
        let ok = [k0, k1, k2].iter().all(|k| k.is_finite()) && k0 > 0.0 && k1 >= 0.0 && k2 >= 0.0;
        if ok {
            Ok(Attenuation { k: [k0, k1, k2] })
        } else {
            Err(Error::InvalidAttenuation { k0, k1, k2 })
        }
    }

    /// The coefficients `[k0, k1, k2]`.
    pub fn coefficients(&self) -> [f32; 3] {
        self.k
    }

    /// `1 / (k0 + k1·d + k2·d²)`.
    #[inline]
    pub fn factor(&self, d: f32) -> f32 {
        let [k0, k1, k2] = self.k;
        1.0 / (k0 + d * (k1 + d * k2))
    }
}

impl Default for Attenuation {
    fn default() -> Self {
        Attenuation::NONE
    }
}

/// A light at infinity: every point sees it from the same direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    to_light: Vec3,
    color: LightColor,
}

/// A light at a point, attenuated with distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    position: Vec3,
    color: LightColor,
    attenuation: Attenuation,
}

/// A point light restricted to a cone, as OpenGL's spotlight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    position: Vec3,
    direction: Vec3,
    cutoff_deg: f32,
    cos_cutoff: f32,
    exponent: f32,
    color: LightColor,
    attenuation: Attenuation,
}

/// A light source: the closed set of light types (pbrt-v4 style tagged enum).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// See [`DirectionalLight`].
    Directional(DirectionalLight),
    /// See [`PointLight`].
    Point(PointLight),
    /// See [`SpotLight`].
    Spot(SpotLight),
}

/// What a light delivers at a point: the unit direction `L` from the point
/// towards the light (zero when undefined: a positional light at the point)
/// and the factor `att · spot` that scales all its terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incidence {
    /// Unit vector from the point towards the light, or zero if undefined.
    pub to_light: Vec3,
    /// `att · spot`, finite and `>= 0`.
    pub factor: f32,
}

fn unit(what: &'static str, v: Vec3) -> Result<Vec3, Error> {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO {
        Err(Error::InvalidDirection {
            what,
            value: v.to_array(),
        })
    } else {
        Ok(n)
    }
}

fn finite(what: &'static str, v: Vec3) -> Result<Vec3, Error> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::InvalidPosition {
            what,
            value: v.to_array(),
        })
    }
}

impl Light {
    /// A directional light; `direction` is the direction the light travels
    /// (so `L = −normalize(direction)`), any non-zero length.
    pub fn directional(direction: Vec3, color: LightColor) -> Result<Self, Error> {
        Ok(Light::Directional(DirectionalLight {
            to_light: -unit("light direction", direction)?,
            color,
        }))
    }

    /// A point light at `position`.
    pub fn point(position: Vec3, color: LightColor, attenuation: Attenuation) -> Result<Self, Error> {
        Ok(Light::Point(PointLight {
            position: finite("light position", position)?,
            color,
            attenuation,
        }))
    }

    /// A spotlight at `position` pointing along `direction`, lighting only
    /// within `cutoff_deg` of its axis (in `[0, 90]`, or 180 for no cone,
    /// as OpenGL), with falloff `max(−L·ŝ, 0)^exponent`, `exponent >= 0`.
    pub fn spot(
        position: Vec3,
        direction: Vec3,
        cutoff_deg: f32,
        exponent: f32,
        color: LightColor,
        attenuation: Attenuation,
    ) -> Result<Self, Error> {
        if !((0.0..=90.0).contains(&cutoff_deg) || cutoff_deg == 180.0) {
            return Err(Error::OutOfRange {
                what: "spot cutoff",
                range: "in [0, 90] degrees, or 180",
                value: cutoff_deg,
            });
        }
        if !(exponent.is_finite() && exponent >= 0.0) {
            return Err(Error::OutOfRange {
                what: "spot exponent",
                range: "finite and >= 0",
                value: exponent,
            });
        }
        Ok(Light::Spot(SpotLight {
            position: finite("light position", position)?,
            direction: unit("spot direction", direction)?,
            cutoff_deg,
            cos_cutoff: cutoff_deg.to_radians().cos(),
            exponent,
            color,
            attenuation,
        }))
    }

    /// The light's colours.
    pub fn color(&self) -> &LightColor {
        match self {
            Light::Directional(l) => &l.color,
            Light::Point(l) => &l.color,
            Light::Spot(l) => &l.color,
        }
    }

    /// The light's position, `None` for a directional light.
    pub fn position(&self) -> Option<Vec3> {
        match self {
            Light::Directional(_) => None,
            Light::Point(l) => Some(l.position),
            Light::Spot(l) => Some(l.position),
        }
    }

    /// The attenuation, `None` for a directional light.
    pub fn attenuation(&self) -> Option<Attenuation> {
        match self {
            Light::Directional(_) => None,
            Light::Point(l) => Some(l.attenuation),
            Light::Spot(l) => Some(l.attenuation),
        }
    }

    /// For a directional light, the unit vector towards the light (`−direction`).
    pub fn to_light(&self) -> Option<Vec3> {
        match self {
            Light::Directional(l) => Some(l.to_light),
            _ => None,
        }
    }

    /// For a spotlight: unit axis, cutoff in degrees, cosine of the cutoff, exponent.
    pub fn spot_cone(&self) -> Option<(Vec3, f32, f32, f32)> {
        match self {
            Light::Spot(l) => Some((l.direction, l.cutoff_deg, l.cos_cutoff, l.exponent)),
            _ => None,
        }
    }

    /// Direction to the light and `att · spot` at `point`.
    ///
    /// Directional: `L = −direction`, factor 1. Point: `L = (P_l − P)/d`,
    /// factor `1/(k0 + k1·d + k2·d²)`. Spot: as point, times
    /// `max(−L·ŝ, 0)^exponent` when `−L·ŝ >= cos(cutoff)`, else 0 (cutoff 180:
    /// spot factor 1). At `d = 0` the direction is undefined: `to_light` is
    /// zero (no diffuse or specular) and the spot factor is taken as 1 (the
    /// apex of the cone). A non-finite `point` gives factor 0.
    #[inline]
    pub fn incidence(&self, point: Vec3) -> Incidence {
        let (position, attenuation) = match self {
            Light::Directional(l) => {
                return Incidence {
                    to_light: l.to_light,
                    factor: 1.0,
                };
            }
            Light::Point(l) => (l.position, l.attenuation),
            Light::Spot(l) => (l.position, l.attenuation),
        };
        let v = position - point;
        let d = v.length();
        if !d.is_finite() {
            return Incidence {
                to_light: Vec3::ZERO,
                factor: 0.0,
            };
        }
        let to_light = if d > 0.0 { v / d } else { Vec3::ZERO };
        let mut factor = attenuation.factor(d);
        if let Light::Spot(s) = self
            && s.cutoff_deg != 180.0
            && d > 0.0
        {
            let c = (-to_light).dot(s.direction);
            factor *= if c >= s.cos_cutoff {
                c.max(0.0).powf(s.exponent)
            } else {
                0.0
            };
        }
        Incidence { to_light, factor }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attenuation_rejects_zero_denominator() {
        assert!(Attenuation::new(1.0, 0.0, 0.05).is_ok());
        assert!(Attenuation::new(0.0, 0.0, 1.0).is_err()); // d = 0 divides by zero
        assert!(Attenuation::new(1.0, -0.5, 0.0).is_err()); // reaches 0 at d = 2
        assert!(Attenuation::new(1.0, 0.0, -1.0).is_err());
        assert!(Attenuation::new(f32::NAN, 0.0, 0.0).is_err());
        let e = Attenuation::new(0.0, 0.0, 1.0).unwrap_err().to_string();
        assert!(e.contains("constant > 0"), "{e}");
    }

    #[test]
    fn attenuation_factor_by_hand() {
        // 1 / (1 + 0.5·2 + 0.25·4) = 1/3
        let a = Attenuation::new(1.0, 0.5, 0.25).unwrap();
        assert!((a.factor(2.0) - 1.0 / 3.0).abs() < 1e-7);
    }

    #[test]
    fn directional_light_travels_along_direction() {
        let l = Light::directional(Vec3::new(0.0, -2.0, 0.0), LightColor::default()).unwrap();
        let i = l.incidence(Vec3::new(5.0, 1.0, 3.0));
        assert_eq!(i.to_light, Vec3::Y);
        assert_eq!(i.factor, 1.0);
        assert!(Light::directional(Vec3::ZERO, LightColor::default()).is_err());
        assert!(Light::directional(Vec3::new(f32::NAN, 0.0, 1.0), LightColor::default()).is_err());
    }

    #[test]
    fn point_light_at_point_has_no_direction() {
        let l = Light::point(
            Vec3::ONE,
            LightColor::default(),
            Attenuation::new(2.0, 1.0, 0.0).unwrap(),
        )
        .unwrap();
        let i = l.incidence(Vec3::ONE);
        assert_eq!(i.to_light, Vec3::ZERO);
        assert_eq!(i.factor, 0.5);
        let i = l.incidence(Vec3::new(1.0, 1.0, f32::NAN));
        assert_eq!(i.factor, 0.0);
    }

    #[test]
    fn spot_factor_by_hand() {
        // Spot at origin pointing down −y, cutoff 30°, exponent 2.
        let s = Light::spot(
            Vec3::ZERO,
            -Vec3::Y,
            30.0,
            2.0,
            LightColor::default(),
            Attenuation::NONE,
        )
        .unwrap();
        // Straight below: −L·ŝ = 1, factor 1.
        assert!((s.incidence(Vec3::new(0.0, -3.0, 0.0)).factor - 1.0).abs() < 1e-6);
        // 20° off axis: cos 20° = 0.9396926, squared 0.8830222.
        let p = Vec3::new(20f32.to_radians().sin(), -20f32.to_radians().cos(), 0.0) * 2.0;
        assert!((s.incidence(p).factor - 0.883_022_2).abs() < 1e-5);
        // 40° off axis: outside the cone.
        let p = Vec3::new(40f32.to_radians().sin(), -40f32.to_radians().cos(), 0.0);
        assert_eq!(s.incidence(p).factor, 0.0);
        // Cutoff 180: no cone, even behind.
        let s = Light::spot(
            Vec3::ZERO,
            -Vec3::Y,
            180.0,
            2.0,
            LightColor::default(),
            Attenuation::NONE,
        )
        .unwrap();
        assert_eq!(s.incidence(Vec3::Y).factor, 1.0);
        assert!(
            Light::spot(
                Vec3::ZERO,
                -Vec3::Y,
                120.0,
                1.0,
                LightColor::default(),
                Attenuation::NONE
            )
            .is_err()
        );
        assert!(
            Light::spot(
                Vec3::ZERO,
                -Vec3::Y,
                30.0,
                -1.0,
                LightColor::default(),
                Attenuation::NONE
            )
            .is_err()
        );
    }

    #[test]
    fn light_colors_validate() {
        assert!(LightColor::uniform(Color::new(1.0, -1.0, 0.0)).is_err());
        let c = LightColor::uniform(Color::splat(0.5)).unwrap();
        assert_eq!(c.ambient(), Color::BLACK);
        assert_eq!(c.diffuse(), Color::splat(0.5));
        assert_eq!(c.specular(), Color::splat(0.5));
    }
}
