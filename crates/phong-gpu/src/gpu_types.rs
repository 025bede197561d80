//! `#[repr(C)]` mirrors of the WGSL structs in `shade.wgsl`, `frame.wgsl`, `raster.wgsl` and `shade_cases.wgsl`
//! (under `shaders/`),
//! all made of 16-byte vectors so that Rust and WGSL layouts agree without padding rules.

use bytemuck::{Pod, Zeroable};
use phong_core::{
    Color, Interpolation, Light, LyonLambda, Material, Normalization, Output, ShadingSettings, SpecularModel, View,
};

/// WGSL `Light`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLight {
    kind: [u32; 4],
    position: [f32; 4],
    direction: [f32; 4],
    ambient: [f32; 4],
    diffuse: [f32; 4],
    specular: [f32; 4],
    attenuation: [f32; 4],
}

fn v4(c: Color, w: f32) -> [f32; 4] {
    [c.r, c.g, c.b, w]
}

impl From<&Light> for GpuLight {
    fn from(l: &Light) -> Self {
        let c = l.color();
        let (kind, position) = match l {
            Light::Directional(_) => (0, l.to_light().unwrap_or_default()),
            Light::Point(_) => (1, l.position().unwrap_or_default()),
            Light::Spot(_) => (2, l.position().unwrap_or_default()),
        };
        let (axis, cutoff, cos_cutoff, exponent) = l.spot_cone().unwrap_or_default();
        let [k0, k1, k2] = l.attenuation().map_or([1.0, 0.0, 0.0], |a| a.coefficients());
        GpuLight {
            kind: [kind, u32::from(kind == 2 && cutoff == 180.0), 0, 0],
            position: [position.x, position.y, position.z, 0.0],
            direction: [axis.x, axis.y, axis.z, cos_cutoff],
            ambient: v4(c.ambient(), exponent),
            diffuse: v4(c.diffuse(), 0.0),
            specular: v4(c.specular(), 0.0),
            attenuation: [k0, k1, k2, 0.0],
        }
    }
}

/// WGSL `ObjectParams`: a material and the shading options of one object.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuObject {
    ambient: [f32; 4],
    diffuse: [f32; 4],
    specular: [f32; 4],
    emission: [f32; 4],
    model: [u32; 4],
    flags: [u32; 4],
    mode: [u32; 4],
    view: [f32; 4],
}

impl GpuObject {
    /// The parameters of an object with material `m`, settings `s` and view `view`.
    pub fn new(m: &Material, s: &ShadingSettings, view: &View) -> Self {
        let o = &s.options;
        let (model, squarings, lambda) = match o.specular {
            SpecularModel::None => (0, 0, 0),
            SpecularModel::Phong => (1, 0, 0),
            SpecularModel::BlinnPhong => (2, 0, 0),
            SpecularModel::Lyon { squarings, lambda } => (3, squarings, u32::from(lambda == LyonLambda::Difference)),
        };
        let normalization = match o.normalization {
            Normalization::None => 0,
            Normalization::Phong => 1,
            Normalization::BlinnPhong => 2,
            Normalization::BlinnPhongExact => 3,
        };
        let (viewer, v) = match *view {
            View::Local { eye } => (0, eye),
            View::Infinite { to_viewer } => (1, to_viewer),
        };
        let interpolation = match s.interpolation {
            Interpolation::Flat => 0,
            Interpolation::Gouraud => 1,
            Interpolation::Phong => 2,
        };
        let output = match s.output {
            Output::Color => 0,
            Output::Ambient => 1,
            Output::Diffuse => 2,
            Output::Specular => 3,
            Output::Normal => 4,
            Output::Depth => 5,
        };
        GpuObject {
            ambient: v4(m.ambient(), 0.0),
            diffuse: v4(m.diffuse(), 0.0),
            specular: v4(m.specular(), 0.0),
            emission: v4(m.emission(), m.shininess()),
            model: [model, squarings, lambda, normalization],
            flags: [
                u32::from(o.gate_specular),
                u32::from(o.clamp),
                u32::from(o.two_sided),
                viewer,
            ],
            mode: [interpolation, output, 0, 0],
            view: [v.x, v.y, v.z, 0.0],
        }
    }
}

/// WGSL `Frame`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuFrame {
    /// Column-major `clip_from_world`.
    pub clip_from_world: [f32; 16],
    /// Camera position, near.
    pub eye: [f32; 4],
    /// View direction, far.
    pub forward: [f32; 4],
    /// Global ambient light.
    pub ambient: [f32; 4],
    /// Number of lights.
    pub counts: [u32; 4],
}

/// WGSL `VsIn`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVertex {
    /// World position.
    pub position: [f32; 3],
    /// Normal (facet normal for flat shading).
    pub normal: [f32; 3],
    /// Flat shading: the triangle's centroid.
    pub centroid: [f32; 3],
    /// Texture coordinates: the mesh's first set, then its second (0 where it has none).
    pub uv: [f32; 4],
    /// The vertex colour (white where the mesh has none).
    pub color: [f32; 3],
    /// The tangent, `w` the bitangent's sign (zero where the mesh has none).
    pub tangent: [f32; 4],
}

/// WGSL `Maps` (render.wgsl): an object's texture maps, bound with its textures.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, Default)]
pub struct GpuMaps {
    /// Whether the diffuse, ambient, specular and emission maps are set.
    pub present: [u32; 4],
    /// Whether the shininess and alpha maps are set; their channels (R, G, B, A, luminance).
    pub scalar: [u32; 4],
    /// x: the alpha cutoff; y: 1 with an alpha test; z: 1 for a textured object; w: the
    /// material's alpha.
    pub cutoff: [f32; 4],
    /// x: 1 for a blended object (its fragments carry their alpha); y: 1 where vertex colours
    /// tint the diffuse texel.
    pub blend: [f32; 4],
    /// A normal map: x 1 where there is one, y its scale, z 1 for green along −v.
    pub normal: [f32; 4],
    /// A metallic-roughness map: x 1 where there is one, y the metallic factor, z the
    /// roughness factor; w 1 with an occlusion map.
    pub pbr: [f32; 4],
    /// The metallic-roughness map's base colour factor (RGB); w the occlusion's strength.
    pub base: [f32; 4],
    /// Per map (diffuse, ambient, specular, emission, shininess, alpha, normal,
    /// metallic-roughness, occlusion): its transform's linear part by columns, then its offset
    /// (xy) and the set of coordinates it reads (z).
    pub transforms: [[f32; 4]; 18],
}

/// WGSL `Case` (compute tests).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuCase {
    /// Position.
    pub position: [f32; 4],
    /// Normal.
    pub normal: [f32; 4],
}

/// WGSL `Globals` (compute tests).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuGlobals {
    /// Global ambient light.
    pub ambient: [f32; 4],
    /// x: lights, y: cases.
    pub counts: [u32; 4],
}

/// WGSL `Raster` (raster.wgsl): the compute rasterizer's frame constants.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuRaster {
    /// Width, height, vertices, triangles.
    pub size: [u32; 4],
    /// The premultiplied background.
    pub background: [f32; 4],
    /// x: the tile item capacity; y: samples per pixel.
    pub items: [u32; 4],
    /// The sample offsets' bounds in 1/256 pixel: min x, max x, min y, max y.
    pub span: [i32; 4],
    /// The sample offsets in 1/256 pixel (x, y, unused, unused).
    pub pattern: [[i32; 4]; 16],
}
