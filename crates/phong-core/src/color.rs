//! Linear RGB colours.
//!
//! Colours are linear (not sRGB-encoded) `f32` triples. Sums and the
//! component-wise product (the seeds' ⊗, seed 000 slides 71–95) are the only
//! arithmetic the illumination model needs. Encoding to 8-bit sRGB or linear
//! bytes happens when an image is written, never here.

use core::ops::{Add, AddAssign, Mul, MulAssign};

/// A linear RGB colour in `f32`, components usually in `[0, 1]` but not
/// restricted: light intensities and unclamped sums may exceed 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Color {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
}

impl Color {
    /// Black, `(0, 0, 0)`.
    pub const BLACK: Color = Color::new(0.0, 0.0, 0.0);
    /// White, `(1, 1, 1)`.
    pub const WHITE: Color = Color::new(1.0, 1.0, 1.0);

    /// `(r, g, b)`.
    #[inline]
    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Color { r, g, b }
    }

    /// The grey `(v, v, v)`.
    #[inline]
    pub const fn splat(v: f32) -> Self {
        Color::new(v, v, v)
    }

    /// From `[r, g, b]`.
    #[inline]
    pub const fn from_array(a: [f32; 3]) -> Self {
        Color::new(a[0], a[1], a[2])
    }

    /// As `[r, g, b]`.
    #[inline]
    pub const fn to_array(self) -> [f32; 3] {
        [self.r, self.g, self.b]
    }

    /// Each component clamped to `[0, 1]`: `clamp(c, 0, 1)` (seed 001's GLSL
    /// `clamp(..., 0., 1.)`). NaN components become 0.
    #[inline]
    #[allow(clippy::manual_clamp)] // `clamp` would keep NaN; this maps it to 0.
    pub fn clamp01(self) -> Self {
        // `f32::clamp` keeps NaN; `max` then `min` maps NaN to the bound.
        let c = |v: f32| v.max(0.0).min(1.0);
        Color::new(c(self.r), c(self.g), c(self.b))
    }

    /// True when every component is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    /// True when every component is finite and `>= 0`.
    #[inline]
    pub fn is_finite_non_negative(self) -> bool {
        self.is_finite() && self.r >= 0.0 && self.g >= 0.0 && self.b >= 0.0
    }

    /// The largest component.
    #[inline]
    pub fn max_component(self) -> f32 {
        self.r.max(self.g).max(self.b)
    }
}

impl Add for Color {
    type Output = Color;
    /// Component-wise sum.
    #[inline]
    fn add(self, o: Color) -> Color {
        Color::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}

impl AddAssign for Color {
    #[inline]
    fn add_assign(&mut self, o: Color) {
        *self = *self + o;
    }
}

impl Mul for Color {
    type Output = Color;
    /// The component-wise product `a ⊗ b` of the seeds.
    #[inline]
    fn mul(self, o: Color) -> Color {
        Color::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}

impl Mul<f32> for Color {
    type Output = Color;
    /// Scaling by a scalar.
    #[inline]
    fn mul(self, k: f32) -> Color {
        Color::new(self.r * k, self.g * k, self.b * k)
    }
}

impl Mul<Color> for f32 {
    type Output = Color;
    /// Scaling by a scalar.
    #[inline]
    fn mul(self, c: Color) -> Color {
        c * self
    }
}

impl MulAssign<f32> for Color {
    #[inline]
    fn mul_assign(&mut self, k: f32) {
        *self = *self * k;
    }
}

impl From<[f32; 3]> for Color {
    fn from(a: [f32; 3]) -> Self {
        Color::from_array(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_is_component_wise() {
        let a = Color::new(0.5, 0.25, 2.0);
        let b = Color::new(0.5, 4.0, 0.25);
        assert_eq!(a * b, Color::new(0.25, 1.0, 0.5));
        assert_eq!(a + b, Color::new(1.0, 4.25, 2.25));
        assert_eq!(2.0 * a, Color::new(1.0, 0.5, 4.0));
    }

    #[test]
    fn clamp_maps_nan_and_range() {
        let c = Color::new(f32::NAN, -0.5, 1.5).clamp01();
        assert_eq!(c, Color::new(0.0, 0.0, 1.0));
        assert!(Color::new(0.1, 0.2, 0.3).is_finite_non_negative());
        assert!(!Color::new(0.1, -0.2, 0.3).is_finite_non_negative());
        assert!(!Color::new(0.1, f32::INFINITY, 0.3).is_finite_non_negative());
    }
}
