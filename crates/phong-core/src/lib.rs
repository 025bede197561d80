//! # phong-core
//!
//! The Phong illumination model, exactly: colours, materials, lights, the
//! options of the model and [`shade`], the scalar shading function that is
//! the specification every phong renderer (CPU kernels, WGSL shaders) is
//! tested against.
//!
//! Pure: no I/O, no threads, no `unsafe`.
//!
//! ```
//! use phong_core::{shade, Color, Light, LightColor, Lighting, Material, ShadingOptions, SurfacePoint, View};
//! use glam::Vec3;
//!
//! // A white light straight above a surface facing up, viewer straight above too.
//! let light = Light::directional(Vec3::new(0.0, -1.0, 0.0), LightColor::uniform(Color::WHITE)?)?;
//! let lighting = Lighting::new(Color::splat(0.2), vec![light])?;
//! let gold = Material::named("gold")?;
//! let point = SurfacePoint { position: Vec3::ZERO, normal: Vec3::Y };
//! let view = View::Local { eye: Vec3::new(0.0, 5.0, 0.0) };
//! let s = shade(&point, &view, &gold, &lighting, &ShadingOptions::default());
//!
//! // N·L = 1 and N·H = 1: c = a_m·0.2 + d_m + s_m, clamped to [0, 1].
//! let expected = (gold.ambient() * 0.2 + gold.diffuse() + gold.specular()).clamp01();
//! assert!((s.color.r - expected.r).abs() < 1e-6);
//! assert!((s.diffuse.g - gold.diffuse().g).abs() < 1e-6);
//! # Ok::<(), phong_core::Error>(())
//! ```
#![forbid(unsafe_code)]

mod camera;
mod color;
mod error;
mod image;
pub mod join;
mod light;
pub mod limits;
mod maps;
mod material;
pub mod mesh;
pub mod primitives;
mod scene;
mod shading;
pub mod text;
pub mod texture;

pub use camera::{Camera, Projection, Viewer, window_from_clip};
pub use color::Color;
pub use error::Error;
pub use image::{Canvas, Encoding, Image, Image8};
pub use light::{Attenuation, DirectionalLight, Incidence, Light, LightColor, PointLight, SpotLight};
pub use maps::{Channel, Maps, MetalRough, NormalMap, Occlusion, Texels, TextureMap, UvTransform, perturb};
pub use material::{Material, NamedMaterial, named_materials, nearest_names, normalize_name};
pub use mesh::Mesh;
pub use scene::{
    ImageSettings, Interpolation, Label, Object, Output, Samples, Scene, ShadingSettings, depth_color, normal_color,
};
pub use shading::{
    Lighting, Lit, LyonLambda, Normalization, Shading, ShadingOptions, SpecularModel, SurfacePoint, View, light, lyon,
    pow_positive, shade, shade_textured, specular_factor,
};
pub use texture::{Filter, MipFilter, Sampler, SharedBytes, Texture, Wrap};

/// The math types phong uses (re-exported from glam).
pub use glam;
