//! The core crate's error type.

use thiserror::Error;

/// Why a value of the model could not be built.
///
/// Every constructor of the core crate validates its input, so that a
/// [`Material`](crate::Material) or [`Light`](crate::Light) that exists is
/// valid; this is what they return when it is not.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A colour component is negative, NaN or infinite.
    #[error("{what} must be finite and non-negative, got [{}, {}, {}]", .value[0], .value[1], .value[2])]
    InvalidColor {
        /// Which colour (e.g. "material diffuse").
        what: &'static str,
        /// The offending value.
        value: [f32; 3],
    },
    /// A scalar is out of its range.
    #[error("{what} must be {range}, got {value}")]
    OutOfRange {
        /// Which quantity (e.g. "shininess").
        what: &'static str,
        /// The allowed range, in words.
        range: &'static str,
        /// The offending value.
        value: f32,
    },
    /// A direction vector has zero length or a non-finite component.
    #[error("{what} must be a finite, non-zero vector, got [{}, {}, {}]", .value[0], .value[1], .value[2])]
    InvalidDirection {
        /// Which direction.
        what: &'static str,
        /// The offending value.
        value: [f32; 3],
    },
    /// A position has a non-finite component.
    #[error("{what} must be finite, got [{}, {}, {}]", .value[0], .value[1], .value[2])]
    InvalidPosition {
        /// Which position.
        what: &'static str,
        /// The offending value.
        value: [f32; 3],
    },
    /// The attenuation `1/(k0 + k1·d + k2·d²)` could divide by zero or go
    /// negative for some distance `d >= 0`.
    #[error(
        "attenuation [{k0}, {k1}, {k2}] is invalid: need constant > 0 and linear, quadratic >= 0 (all finite), \
         so that k0 + k1·d + k2·d² never reaches 0; for inverse-square falloff use e.g. [1, 0, 1]"
    )]
    InvalidAttenuation {
        /// Constant coefficient.
        k0: f32,
        /// Linear coefficient.
        k1: f32,
        /// Quadratic coefficient.
        k2: f32,
    },
    /// Values that are each valid but do not work together (e.g. a camera's up vector
    /// parallel to its view direction).
    #[error("{0}")]
    Degenerate(String),
    /// An image no renderer draws: a side of 0 or past
    /// [`MAX_IMAGE_DIMENSION`](crate::limits::MAX_IMAGE_DIMENSION), or more pixels × samples
    /// than [`MAX_SAMPLES_TOTAL`](crate::limits::MAX_SAMPLES_TOTAL).
    #[error(
        "image {width}x{height} with {samples} samples per pixel cannot be rendered (each side from 1 to 16384 \
         pixels, and at most 16384x16384x4 samples in all)"
    )]
    ImageSize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Samples per pixel.
        samples: u32,
    },
    /// No built-in material has this name.
    #[error("unknown material {name:?}{}", suggest(.suggestions))]
    UnknownMaterial {
        /// The name asked for.
        name: String,
        /// The nearest known names, best first.
        suggestions: Vec<&'static str>,
    },
}

fn suggest(s: &[&'static str]) -> String {
    if s.is_empty() {
        String::new()
    } else {
        format!("; did you mean {}?", s.join(", "))
    }
}
