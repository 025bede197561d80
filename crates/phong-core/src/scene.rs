//! A scene as plain data: what a renderer needs, already resolved and
//! validated (world space, linear RGB). File formats build it; renderers
//! read it.

use crate::{
    Camera, Color, Encoding, Error, Lighting, Maps, Material, Mesh, Shading, ShadingOptions, SurfacePoint, View,
    Viewer, light, shade,
};
use glam::Vec3;

/// Where lighting is computed (seed 001: per-vertex vs per-fragment).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// One colour per triangle, lit with its facet normal at its centroid.
    Flat,
    /// Lit at the vertices, colours interpolated (Gouraud; OpenGL's fixed function).
    Gouraud,
    /// Normals and positions interpolated and renormalised, lit per pixel.
    #[default]
    Phong,
}

/// What the image shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Output {
    /// The lit colour.
    #[default]
    Color,
    /// Emission plus the ambient terms.
    Ambient,
    /// The diffuse term.
    Diffuse,
    /// The specular term.
    Specular,
    /// The world-space unit normal as `0.5·n + 0.5`.
    Normal,
    /// Linear view depth, white at `near` to black at `far`.
    Depth,
}

impl Output {
    /// The term of `s` this output shows (the colour for the normal and depth outputs, which
    /// are not terms of the equation).
    #[inline]
    pub fn term(self, s: &Shading) -> Color {
        match self {
            Output::Ambient => s.ambient,
            Output::Diffuse => s.diffuse,
            Output::Specular => s.specular,
            _ => s.color,
        }
    }
}

/// The normal output's colour for unit normal `n`: `0.5·n + 0.5`, black for a zero normal.
#[inline]
pub fn normal_color(n: Vec3) -> Color {
    if n == Vec3::ZERO {
        Color::BLACK
    } else {
        Color::new(n.x * 0.5 + 0.5, n.y * 0.5 + 0.5, n.z * 0.5 + 0.5)
    }
}

/// The depth output's grey for world point `p`: 1 at `near` to 0 at `far`, clamped.
#[inline]
pub fn depth_color(camera: &Camera, p: Vec3) -> Color {
    let d = camera.depth_of(p);
    Color::splat((1.0 - (d - camera.near()) / (camera.far() - camera.near())).clamp(0.0, 1.0))
}

/// Samples per pixel: the counts every renderer draws, so that no other can be asked for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Samples {
    /// One sample at the pixel's centre.
    #[default]
    One,
    /// The standard 4-sample rotated grid.
    Four,
    /// A 4×4 grid.
    Sixteen,
}

impl Samples {
    /// Every count, smallest first.
    pub const ALL: [Samples; 3] = [Samples::One, Samples::Four, Samples::Sixteen];

    /// How many samples.
    pub const fn count(self) -> u32 {
        match self {
            Samples::One => 1,
            Samples::Four => 4,
            Samples::Sixteen => 16,
        }
    }

    /// The samples of `n` per pixel: 1, 4 or 16.
    pub fn from_count(n: u32) -> Result<Samples, Error> {
        Samples::ALL
            .into_iter()
            .find(|s| s.count() == n)
            .ok_or(Error::OutOfRange {
                what: "antialias",
                range: "1, 4 or 16 samples per pixel",
                value: n as f32,
            })
    }
}

impl std::fmt::Display for Samples {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.count())
    }
}

/// The image's settings. Renderers take them through [`ImageSettings::check`], the one place
/// the size limits are decided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageSettings {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Background, linear RGBA (alpha < 1 gives an RGBA PNG).
    pub background: [f32; 4],
    /// Samples per pixel.
    pub samples: Samples,
    /// 8-bit encoding of the output.
    pub encoding: Encoding,
}

impl Default for ImageSettings {
    fn default() -> Self {
        ImageSettings {
            width: 800,
            height: 600,
            background: [0.0, 0.0, 0.0, 1.0],
            samples: Samples::One,
            encoding: Encoding::Linear,
        }
    }
}

impl ImageSettings {
    /// The image can be rendered: each side from 1 to
    /// [`MAX_IMAGE_DIMENSION`](crate::limits::MAX_IMAGE_DIMENSION), pixels × samples at most
    /// [`MAX_SAMPLES_TOTAL`](crate::limits::MAX_SAMPLES_TOTAL).
    pub fn check(&self) -> Result<(), Error> {
        let (w, h, s) = (self.width, self.height, self.samples.count());
        let side = 1..=crate::limits::MAX_IMAGE_DIMENSION;
        if side.contains(&w) && side.contains(&h) && self.samples_total() <= crate::limits::MAX_SAMPLES_TOTAL {
            Ok(())
        } else {
            Err(Error::ImageSize {
                width: w,
                height: h,
                samples: s,
            })
        }
    }

    /// Pixels × samples per pixel.
    pub fn samples_total(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height) * u64::from(self.samples.count())
    }
}

/// How the scene is shaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingSettings {
    /// The model's options.
    pub options: ShadingOptions,
    /// Where lighting is evaluated.
    pub interpolation: Interpolation,
    /// Local or infinite viewer.
    pub viewer: Viewer,
    /// What the image shows.
    pub output: Output,
}

/// A mesh in world space with its material and how it is shaded (the
/// scene's settings, or the object's own overrides, so that one image can
/// compare models, interpolations or terms side by side).
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// A name for messages (the shape, or the file and group).
    pub name: String,
    /// World-space geometry.
    pub mesh: Mesh,
    /// Its material.
    pub material: Material,
    /// How it is shaded.
    pub shading: ShadingSettings,
    /// Its material's texture maps (none by default); they need the mesh's texture
    /// coordinates.
    pub maps: Maps,
}

impl Object {
    /// Lights a point of this object as the renderers do: two-sided lighting is the caller's,
    /// decided by the polygon's facing (a back face is lit with its normal flipped, OpenGL's
    /// rule), so the per-point flip of [`shade`] is off.
    #[inline]
    pub fn shade(&self, lighting: &Lighting, view: &View, position: Vec3, normal: Vec3) -> Shading {
        let options = ShadingOptions {
            two_sided: false,
            ..self.shading.options
        };
        shade(
            &SurfacePoint { position, normal },
            view,
            &self.material,
            lighting,
            &options,
        )
    }

    /// The light at a vertex (Gouraud) or a triangle's centroid (flat), as the object's output
    /// shows it: `(colour, black)`, or for a textured object `(primary, specular)` ([`Lit`]
    /// with every term in the primary colour), the texels applied per pixel by
    /// [`Lit::modulate`]. Under Gouraud and flat shading the ambient, emission and shininess
    /// maps have no effect: the light is not computed per pixel.
    ///
    /// [`Lit`]: crate::Lit
    /// [`Lit::modulate`]: crate::Lit::modulate
    pub fn vertex_light(&self, lighting: &Lighting, view: &View, p: Vec3, n: Vec3) -> (Color, Color) {
        let output = self.shading.output;
        if !self.textured() {
            return (output.term(&self.shade(lighting, view, p, n)), Color::BLACK);
        }
        let options = ShadingOptions {
            two_sided: false,
            ..self.shading.options
        };
        let point = SurfacePoint { position: p, normal: n };
        let (lit, [e, a, d, s]) = light(&point, view, &self.material, 1.0, (false, false), lighting, &options);
        match output {
            Output::Color => (lit.primary, lit.specular),
            Output::Ambient => (e + a, Color::BLACK),
            Output::Diffuse => (d, Color::BLACK),
            Output::Specular => (Color::BLACK, s),
            _ => (Color::BLACK, Color::BLACK),
        }
    }

    /// Whether the object is blended: [`Maps::blend`], and an alpha that can be below 1 (the
    /// material's, or a map's with alpha).
    pub fn blends(&self) -> bool {
        self.maps.blend
            && (self.material.alpha() < 1.0
                || (self.textured()
                    && (self.maps.alpha.is_some()
                        || self.maps.diffuse.as_ref().is_some_and(|m| m.texture.has_alpha()))))
    }

    /// The alpha of a point of this object that is not textured: the material's where it
    /// blends, else 1.
    pub fn plain_alpha(&self) -> f32 {
        if self.blends() { self.material.alpha() } else { 1.0 }
    }

    /// Whether the object is drawn with per-pixel texels: it has maps and texture coordinates,
    /// or vertex colours (which multiply the diffuse texel: see [`Texels::tinted`]).
    ///
    /// [`Texels::tinted`]: crate::Texels::tinted
    #[inline]
    pub fn textured(&self) -> bool {
        (!self.maps.is_empty() && self.mesh.has_uvs()) || !self.mesh.colors().is_empty()
    }
}

/// Text drawn over the image, centred at the projection of a world point
/// (e.g. a material's name under its teapot).
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// The text (ASCII; other characters are drawn as `?`).
    pub text: String,
    /// World-space anchor: the text's centre.
    pub position: glam::Vec3,
    /// Linear RGB colour.
    pub color: Color,
    /// Pixels per font pixel (the font is 5×7).
    pub size: u32,
}

/// Everything a renderer needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Image settings.
    pub image: ImageSettings,
    /// The camera.
    pub camera: Camera,
    /// Ambient light and lights.
    pub lighting: Lighting,
    /// The objects.
    pub objects: Vec<Object>,
    /// Text over the image.
    pub labels: Vec<Label>,
}

impl Scene {
    /// Number of triangles in all objects.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.triangles().len()).sum()
    }

    /// The order every renderer draws the objects in: the opaque ones as listed, then the
    /// blended ones ([`Object::blends`]) back to front, by the distance of their bounds' centre
    /// along the camera's view direction (farthest first; ties as listed).
    pub fn draw_order(&self) -> Vec<usize> {
        let (eye, forward) = (self.camera.eye(), self.camera.forward());
        let depth = |o: &Object| {
            o.mesh
                .bounds()
                .map_or(0.0, |(lo, hi)| ((lo + hi) * 0.5 - eye).dot(forward))
        };
        let mut order: Vec<usize> = (0..self.objects.len()).filter(|&i| !self.objects[i].blends()).collect();
        let mut blended: Vec<(f32, usize)> = (0..self.objects.len())
            .filter(|&i| self.objects[i].blends())
            .map(|i| (depth(&self.objects[i]), i))
            .collect();
        blended.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        order.extend(blended.into_iter().map(|(_, i)| i));
        order
    }
}
