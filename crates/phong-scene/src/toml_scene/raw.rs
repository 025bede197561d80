//! The scene file as serde reads it: every key with its span where a value is checked
//! later, unknown keys refused (`deny_unknown_fields`).

use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// A value with its byte range in the file.
pub(crate) type S<T> = Spanned<T>;

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub image: Option<RawImage>,
    pub camera: Option<RawCamera>,
    pub shading: Option<RawShading>,
    #[serde(default)]
    pub light: Vec<S<RawLight>>,
    #[serde(default)]
    pub materials: BTreeMap<String, S<RawMaterial>>,
    #[serde(default)]
    pub object: Vec<S<RawObject>>,
    #[serde(default)]
    pub label: Vec<S<RawLabel>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLabel {
    pub text: S<String>,
    pub position: S<Vec<f32>>,
    pub color: Option<S<Vec<f32>>>,
    pub size: Option<S<i64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawImage {
    pub width: Option<S<i64>>,
    pub height: Option<S<i64>>,
    pub background: Option<S<Vec<f32>>>,
    pub antialias: Option<S<i64>>,
    pub encoding: Option<S<String>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCamera {
    pub projection: Option<S<String>>,
    pub position: Option<S<Vec<f32>>>,
    pub target: Option<S<Vec<f32>>>,
    pub up: Option<S<Vec<f32>>>,
    pub fov: Option<S<f32>>,
    pub height: Option<S<f32>>,
    pub near: Option<S<f32>>,
    pub far: Option<S<f32>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawShading {
    pub model: Option<S<String>>,
    pub interpolation: Option<S<String>>,
    pub viewer: Option<S<String>>,
    pub ambient: Option<S<Vec<f32>>>,
    pub normalization: Option<S<String>>,
    pub two_sided: Option<bool>,
    pub output: Option<S<String>>,
    pub gate_specular: Option<bool>,
    pub clamp: Option<bool>,
    pub lyon_squarings: Option<S<i64>>,
    pub lyon_lambda: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLight {
    #[serde(rename = "type")]
    pub kind: S<String>,
    pub direction: Option<S<Vec<f32>>>,
    pub position: Option<S<Vec<f32>>>,
    pub color: Option<S<Vec<f32>>>,
    pub ambient: Option<S<Vec<f32>>>,
    pub diffuse: Option<S<Vec<f32>>>,
    pub specular: Option<S<Vec<f32>>>,
    pub attenuation: Option<S<Vec<f32>>>,
    pub cutoff: Option<S<f32>>,
    pub exponent: Option<S<f32>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMaterial {
    pub base: Option<S<String>>,
    pub paint: Option<S<Vec<f32>>>,
    pub ambient: Option<S<Vec<f32>>>,
    pub diffuse: Option<S<Vec<f32>>>,
    pub specular: Option<S<Vec<f32>>>,
    pub emission: Option<S<Vec<f32>>>,
    pub shininess: Option<S<f32>>,
    pub alpha: Option<S<f32>>,
    pub diffuse_map: Option<S<String>>,
    pub ambient_map: Option<S<String>>,
    pub specular_map: Option<S<String>>,
    pub emission_map: Option<S<String>>,
    pub shininess_map: Option<S<String>>,
    pub alpha_map: Option<S<String>>,
    pub normal_map: Option<S<String>>,
    pub bump_map: Option<S<String>>,
    pub bump_scale: Option<S<f32>>,
    pub uv_scale: Option<S<Vec<f32>>>,
    pub uv_offset: Option<S<Vec<f32>>>,
    pub wrap: Option<S<String>>,
    pub filter: Option<S<String>>,
    pub encoding: Option<S<String>>,
    pub alpha_cutoff: Option<S<f32>>,
    pub blend: Option<S<bool>>,
    pub normal_scale: Option<S<f32>>,
    pub normal_green: Option<S<String>>,
}

/// An inline material table: the same keys, without per-key spans (serde's
/// untagged enums cannot carry them); its own span, on one line, is used.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PlainMaterial {
    pub base: Option<String>,
    pub paint: Option<Vec<f32>>,
    pub ambient: Option<Vec<f32>>,
    pub diffuse: Option<Vec<f32>>,
    pub specular: Option<Vec<f32>>,
    pub emission: Option<Vec<f32>>,
    pub shininess: Option<f32>,
    pub alpha: Option<f32>,
    pub diffuse_map: Option<String>,
    pub ambient_map: Option<String>,
    pub specular_map: Option<String>,
    pub emission_map: Option<String>,
    pub shininess_map: Option<String>,
    pub alpha_map: Option<String>,
    pub normal_map: Option<String>,
    pub bump_map: Option<String>,
    pub bump_scale: Option<f32>,
    pub uv_scale: Option<Vec<f32>>,
    pub uv_offset: Option<Vec<f32>>,
    pub wrap: Option<String>,
    pub filter: Option<String>,
    pub encoding: Option<String>,
    pub alpha_cutoff: Option<f32>,
    pub blend: Option<bool>,
    pub normal_scale: Option<f32>,
    pub normal_green: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged)]
pub(crate) enum MaterialRef {
    Name(String),
    Inline(Box<PlainMaterial>),
}

#[derive(Deserialize)]
#[serde(untagged)]
pub(crate) enum Scale {
    Uniform(f32),
    Axes(Vec<f32>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawObject {
    pub shape: Option<S<String>>,
    pub mesh: Option<S<String>>,
    pub fit: Option<S<bool>>,
    pub segments: Option<S<i64>>,
    pub radius: Option<S<f32>>,
    pub tube: Option<S<f32>>,
    pub material: Option<S<MaterialRef>>,
    pub position: Option<S<Vec<f32>>>,
    pub rotation: Option<S<Vec<f32>>>,
    pub scale: Option<S<Scale>>,
    pub normals: Option<S<String>>,
    pub crease: Option<S<f32>>,
    pub model: Option<S<String>>,
    pub interpolation: Option<S<String>>,
    pub output: Option<S<String>>,
}
