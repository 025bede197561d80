//! A material's texture maps and what they give at a point (see [`shade_textured`] for the
//! equation they enter).
//!
//! [`shade_textured`]: crate::shade_textured

use crate::texture::{Sampler, Texture};
use crate::{Color, Material};
use glam::{Mat2, Vec2};
use std::sync::Arc;

/// An affine map of texture coordinates, `uv' = linear·uv + offset` (MTL's `-s` and `-o`, a
/// scene's `uv_scale` and `uv_offset`, glTF's KHR_texture_transform).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// The linear part.
    pub linear: Mat2,
    /// The offset.
    pub offset: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        UvTransform {
            linear: Mat2::IDENTITY,
            offset: Vec2::ZERO,
        }
    }
}

impl UvTransform {
    /// Scale, then offset.
    pub fn scale_offset(scale: Vec2, offset: Vec2) -> UvTransform {
        UvTransform {
            linear: Mat2::from_diagonal(scale),
            offset,
        }
    }
    /// `uv` mapped.
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        self.linear * uv + self.offset
    }
    /// This map after `first`: `self(first(uv))`.
    pub fn after(&self, first: &UvTransform) -> UvTransform {
        UvTransform {
            linear: self.linear * first.linear,
            offset: self.linear * first.offset + self.offset,
        }
    }
}

/// Which channel a scalar map (shininess, alpha) reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Red.
    R,
    /// Green.
    G,
    /// Blue.
    B,
    /// Alpha.
    A,
    /// Luminance, `0.2126 R + 0.7152 G + 0.0722 B` (MTL's `-imfchan l`).
    Luminance,
}

impl Channel {
    /// The weights of red, green and blue in [`Channel::Luminance`] (Rec. 709's).
    pub const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

    /// The channel of `rgba`.
    #[inline]
    pub fn of(self, rgba: [f32; 4]) -> f32 {
        match self {
            Channel::R => rgba[0],
            Channel::G => rgba[1],
            Channel::B => rgba[2],
            Channel::A => rgba[3],
            Channel::Luminance => {
                let [r, g, b] = Channel::LUMINANCE;
                r * rgba[0] + g * rgba[1] + b * rgba[2]
            }
        }
    }
}

/// A texture as one map of a material: the image, how it is sampled and where.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureMap {
    /// The image and its mipmaps.
    pub texture: Arc<Texture>,
    /// Wrapping and filtering.
    pub sampler: Sampler,
    /// Applied to the mesh's coordinates before sampling.
    pub transform: UvTransform,
    /// The mesh's texture coordinates it reads: 0 [`crate::Mesh::uvs`], 1
    /// [`crate::Mesh::uvs1`] (glTF's `texCoord`).
    pub set: u8,
}

impl TextureMap {
    /// The map with the default sampler (trilinear, repeat) and no transform.
    pub fn new(texture: Arc<Texture>) -> TextureMap {
        TextureMap {
            texture,
            sampler: Sampler::default(),
            transform: UvTransform::default(),
            set: 0,
        }
    }

    /// The filtered texel at mesh coordinates `uv`, whose screen derivatives are `d_dx` and
    /// `d_dy` (they pass through the transform's linear part into the level of detail).
    #[inline]
    pub fn sample(&self, uv: Vec2, d_dx: Vec2, d_dy: Vec2) -> [f32; 4] {
        let t = &self.transform;
        let lod = self.texture.lod(t.linear * d_dx, t.linear * d_dy);
        self.texture.sample(&self.sampler, t.apply(uv), lod)
    }
}

/// The texture maps of an object's material. Colour maps hold linear values (a file's sRGB
/// colours are decoded where it is read).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Maps {
    /// `map_Kd`: modulates the diffuse colour (and the ambient and emission where they have no
    /// map of their own, as `GL_MODULATE` does); its alpha multiplies the material's.
    pub diffuse: Option<TextureMap>,
    /// `map_Ka`: modulates the ambient terms.
    pub ambient: Option<TextureMap>,
    /// `map_Ks`: modulates the specular term.
    pub specular: Option<TextureMap>,
    /// `map_Ke`: modulates the emission.
    pub emission: Option<TextureMap>,
    /// `map_Ns`: scales the shininess, by one channel.
    pub shininess: Option<(TextureMap, Channel)>,
    /// `map_d`: multiplies the alpha, by one channel.
    pub alpha: Option<(TextureMap, Channel)>,
    /// `norm`, glTF's normal texture: a tangent-space normal map (with Phong interpolation).
    pub normal: Option<NormalMap>,
    /// glTF's metallic-roughness texture, mapped to Phong per texel (see [`MetalRough`]).
    pub metal_rough: Option<MetalRough>,
    /// glTF's occlusion texture: scales the ambient terms (see [`Occlusion`]).
    pub occlusion: Option<Occlusion>,
    /// The alpha test: a point whose alpha is below it is not drawn (`None`: no test).
    pub alpha_cutoff: Option<f32>,
    /// Blending (`GL_BLEND` with `GL_ONE_MINUS_SRC_ALPHA`): the object is drawn after the
    /// opaque ones, over what is behind it by its alpha, without writing depth (see
    /// [`Scene::draw_order`](crate::Scene::draw_order)). Off by default, as in OpenGL: a
    /// material's alpha alone changes nothing.
    pub blend: bool,
}

/// A tangent-space normal map: `n = (2·rgb − 1)` with `x, y` times `scale` (glTF's
/// `normalTexture.scale`), in the frame of the mesh's MikkTSpace tangents; green points along
/// the bitangent (`+v`: OpenGL's, Blender's and glTF's convention) unless `green_down` (DirectX's).
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    /// The image.
    pub map: TextureMap,
    /// Scales the tangential components.
    pub scale: f32,
    /// Green points along `−v`.
    pub green_down: bool,
}

impl NormalMap {
    /// The tangent-space normal map a bump (height) map implies, so that every renderer draws
    /// bump maps as normal maps. Per texel of level 0, the height `h` (`channel`) is differenced
    /// with its neighbours (central differences, wrapping as `sampler` does; mirror and clamp
    /// both repeat the edge texel), and the normal is `normalize(−k·∂h/∂x, −k·∂h/∂y, 1)`, with
    /// `k = scale` (MTL's `-bm`, a scene's `bump_scale`) and the derivatives per texel (`x`
    /// along `+u`, `y` along `+v`), as normal-map tools build them from height maps. It is
    /// stored in 16 bits, sampled with `sampler` and `transform`, and green points along `+v`.
    pub fn from_height(
        height: &Texture,
        channel: Channel,
        scale: f32,
        sampler: Sampler,
        transform: UvTransform,
    ) -> Result<NormalMap, crate::Error> {
        let (w, h) = (height.width(), height.height());
        // The 16-bit result with its mipmaps, checked before it is allocated.
        let bytes = u64::from(w) * u64::from(h) * 8 * 4 / 3;
        if bytes > crate::limits::MAX_TEXTURE_BYTES {
            return Err(crate::Error::OutOfRange {
                what: "normal map made from a bump map, with its mipmaps (bytes)",
                range: "at most 2 GiB",
                value: bytes as f32,
            });
        }
        let at = |x: u32, y: u32| channel.of(height.texel(0, x, y));
        let step = |i: u32, n: u32, d: i64, wrap: crate::Wrap| -> u32 {
            let j = i64::from(i) + d;
            match wrap {
                crate::Wrap::Repeat => j.rem_euclid(i64::from(n)) as u32,
                _ => j.clamp(0, i64::from(n) - 1) as u32,
            }
        };
        let mut top_first = Vec::with_capacity(w as usize * h as usize);
        for y in (0..h).rev() {
            for x in 0..w {
                let (xm, xp) = (step(x, w, -1, sampler.wrap_u), step(x, w, 1, sampler.wrap_u));
                let (ym, yp) = (step(y, h, -1, sampler.wrap_v), step(y, h, 1, sampler.wrap_v));
                let dx = 0.5 * (at(xp, y) - at(xm, y));
                let dy = 0.5 * (at(x, yp) - at(x, ym));
                let n = glam::Vec3::new(-scale * dx, -scale * dy, 1.0).normalize();
                let c = |v: f32| ((v * 0.5 + 0.5) * 65535.0).round() as u16;
                top_first.push([c(n.x), c(n.y), c(n.z), u16::MAX]);
            }
        }
        Ok(NormalMap {
            map: TextureMap {
                texture: Arc::new(Texture::new(w, h, &top_first, 16)?),
                sampler,
                transform,
                set: 0,
            },
            scale: 1.0,
            green_down: false,
        })
    }
}

/// glTF's metallic-roughness texture (metalness in blue, roughness in green) mapped to Phong per
/// texel, as the loader maps a glTF material's factors: with `base = base_factor ⊗ T_Kd`,
/// `m = metallic·T.b`, `r = roughness·T.g`, the texels give diffuse (and ambient)
/// `base·(1 − m)`, specular `mix(0.04, base, m)` and shininess [`MetalRough::shininess`]`(r)`.
/// The material it goes with is [`MetalRough::material`]'s, so that the texels are the terms.
#[derive(Clone, Debug, PartialEq)]
pub struct MetalRough {
    /// The image.
    pub map: TextureMap,
    /// glTF's `baseColorFactor` (RGB).
    pub base_factor: Color,
    /// `metallicFactor`.
    pub metallic: f32,
    /// `roughnessFactor`.
    pub roughness: f32,
}

impl MetalRough {
    /// The highest shininess a roughness maps to (roughness 0 would be infinite).
    pub const MAX_SHININESS: f32 = 10_000.0;

    /// The Blinn-Phong shininess equivalent to a roughness (Beckmann's distribution with
    /// `α = roughness²`): `2/α² − 2`, at most [`MetalRough::MAX_SHININESS`].
    pub fn shininess(roughness: f32) -> f32 {
        let a = roughness.clamp(0.0, 1.0).powi(2);
        if a > 0.0 {
            (2.0 / (a * a) - 2.0).clamp(0.0, Self::MAX_SHININESS)
        } else {
            Self::MAX_SHININESS
        }
    }

    /// The material a metallic-roughness map scales: ambient and diffuse `base_factor`,
    /// specular white, shininess 1, with `emission` and `alpha`.
    pub fn material(&self, emission: Color, alpha: f32) -> Material {
        let m = Material::new(self.base_factor, self.base_factor, Color::WHITE, emission, 1.0).unwrap_or_default();
        m.with_alpha(alpha).unwrap_or(m)
    }
}

/// glTF's occlusion texture: the ambient terms times `1 + strength·(T.r − 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Occlusion {
    /// The image.
    pub map: TextureMap,
    /// glTF's `strength` (1 by default).
    pub strength: f32,
}

/// The normal at a point from an interpolated normal `n`, tangent `t` (`w`: the bitangent's
/// sign) and a tangent-space normal `ts`: `T·x + B·y + N·z` with `N = n/|n|`, `T` the tangent
/// made orthogonal to `N`, `B = w·(N × T)`. Where the tangent is zero or parallel to `n`, `n`.
#[inline]
pub fn perturb(n: glam::Vec3, t: glam::Vec4, ts: glam::Vec3) -> glam::Vec3 {
    let nn = n.normalize_or_zero();
    let tt = (t.truncate() - nn * nn.dot(t.truncate())).normalize_or_zero();
    if tt == glam::Vec3::ZERO || nn == glam::Vec3::ZERO {
        return n;
    }
    let b = nn.cross(tt) * if t.w < 0.0 { -1.0 } else { 1.0 };
    tt * ts.x + b * ts.y + nn * ts.z
}

/// What an object's maps give at one point: `1` (white, full) where a map is absent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texels {
    /// The diffuse map's RGBA.
    pub diffuse: [f32; 4],
    /// The ambient map's colour, if there is one.
    pub ambient: Option<Color>,
    /// The specular map's colour.
    pub specular: Color,
    /// The emission map's colour, if there is one.
    pub emission: Option<Color>,
    /// The shininess factor.
    pub shininess: f32,
    /// The alpha map's value.
    pub alpha: f32,
    /// The normal map's tangent-space normal, if there is one.
    pub normal: Option<glam::Vec3>,
    /// The occlusion map's factor on the ambient terms, if there is one.
    pub occlusion: Option<f32>,
}

impl Default for Texels {
    fn default() -> Self {
        Texels {
            diffuse: [1.0; 4],
            ambient: None,
            specular: Color::WHITE,
            emission: None,
            shininess: 1.0,
            alpha: 1.0,
            normal: None,
            occlusion: None,
        }
    }
}

impl Texels {
    /// What the ambient terms are multiplied by: the ambient map's colour, else the diffuse
    /// texel's, times the occlusion.
    #[inline]
    pub fn ambient_texel(&self) -> Color {
        let t = self.ambient.unwrap_or(rgb(self.diffuse));
        self.occlusion.map_or(t, |o| t * o)
    }

    /// The texels with a vertex colour: it multiplies the diffuse texel's colour, so it
    /// modulates the diffuse, ambient and emission terms as a diffuse map does (with a white
    /// material: OpenGL's `GL_COLOR_MATERIAL` for ambient and diffuse).
    #[inline]
    pub fn tinted(mut self, c: Color) -> Texels {
        self.diffuse[0] *= c.r;
        self.diffuse[1] *= c.g;
        self.diffuse[2] *= c.b;
        self
    }
}

fn rgb(t: [f32; 4]) -> Color {
    Color::new(t[0], t[1], t[2])
}

impl Maps {
    /// Whether no map is set (the alpha test and blending alone are not maps).
    pub fn is_empty(&self) -> bool {
        self.diffuse.is_none()
            && self.ambient.is_none()
            && self.specular.is_none()
            && self.emission.is_none()
            && self.shininess.is_none()
            && self.alpha.is_none()
            && self.normal.is_none()
            && self.metal_rough.is_none()
            && self.occlusion.is_none()
    }

    /// Every map set, for memory accounting and uploads.
    pub fn each(&self) -> impl Iterator<Item = &TextureMap> {
        [&self.diffuse, &self.ambient, &self.specular, &self.emission]
            .into_iter()
            .flatten()
            .chain(self.shininess.iter().map(|(m, _)| m))
            .chain(self.alpha.iter().map(|(m, _)| m))
            .chain(self.normal.iter().map(|n| &n.map))
            .chain(self.metal_rough.iter().map(|m| &m.map))
            .chain(self.occlusion.iter().map(|o| &o.map))
    }

    /// Whether a map reads the mesh's second set of texture coordinates (a set past 1 reads it,
    /// as [`Maps::sample_sets`] does).
    pub fn uses_second_set(&self) -> bool {
        self.each().any(|m| m.set >= 1)
    }

    /// Which terms of the light these maps modulate apart ([`light`](fn@crate::light)'s `split`): the
    /// emission (an emission map) and the ambient terms (an ambient or occlusion map).
    pub fn apart(&self) -> (bool, bool) {
        (
            self.emission.is_some(),
            self.ambient.is_some() || self.occlusion.is_some(),
        )
    }

    /// Samples every map at `uv` with screen derivatives `d_dx`, `d_dy` (one set of
    /// coordinates for every map).
    pub fn sample(&self, uv: Vec2, d_dx: Vec2, d_dy: Vec2) -> Texels {
        self.sample_sets(&[[uv, d_dx, d_dy]; 2])
    }

    /// Samples every map at its set of coordinates ([`TextureMap::set`]): `sets[k]` is set
    /// `k`'s `[uv, ∂uv/∂x, ∂uv/∂y]`.
    pub fn sample_sets(&self, sets: &[[Vec2; 3]; 2]) -> Texels {
        let at = |m: &TextureMap| {
            let [uv, d_dx, d_dy] = sets[usize::from(m.set.min(1))];
            m.sample(uv, d_dx, d_dy)
        };
        let mut t = Texels {
            diffuse: self.diffuse.as_ref().map_or([1.0; 4], at),
            ambient: self.ambient.as_ref().map(|m| rgb(at(m))),
            specular: self.specular.as_ref().map_or(Color::WHITE, |m| rgb(at(m))),
            emission: self.emission.as_ref().map(|m| rgb(at(m))),
            shininess: self.shininess.as_ref().map_or(1.0, |(m, c)| c.of(at(m))),
            alpha: self.alpha.as_ref().map_or(1.0, |(m, c)| c.of(at(m))),
            normal: self.normal.as_ref().map(|n| {
                let t = at(&n.map);
                let y = 2.0 * t[1] - 1.0;
                glam::Vec3::new(
                    (2.0 * t[0] - 1.0) * n.scale,
                    if n.green_down { -y } else { y } * n.scale,
                    2.0 * t[2] - 1.0,
                )
            }),
            occlusion: self
                .occlusion
                .as_ref()
                .map(|o| 1.0 + o.strength * (at(&o.map)[0] - 1.0)),
        };
        if let Some(mr) = &self.metal_rough {
            let s = at(&mr.map);
            let m = (mr.metallic * s[2]).clamp(0.0, 1.0);
            let base = mr.base_factor * rgb(t.diffuse);
            t.specular = Color::splat(0.04 * (1.0 - m)) + base * m;
            t.shininess = MetalRough::shininess(mr.roughness * s[1]);
            for c in &mut t.diffuse[..3] {
                *c *= 1.0 - m;
            }
        }
        t
    }

    /// The alpha of a point of `material` with these texels: the material's alpha times the
    /// diffuse map's and the alpha map's.
    #[inline]
    pub fn alpha(material: &Material, t: &Texels) -> f32 {
        material.alpha() * t.diffuse[3] * t.alpha
    }

    /// [`Maps::alpha`] of the texels at `sets` (as [`Maps::sample_sets`] takes them), sampling
    /// only the diffuse and alpha maps: what the alpha test reads before a point is shaded.
    pub fn alpha_sets(&self, material: &Material, sets: &[[Vec2; 3]; 2]) -> f32 {
        let at = |m: &TextureMap| {
            let [uv, d_dx, d_dy] = sets[usize::from(m.set.min(1))];
            m.sample(uv, d_dx, d_dy)
        };
        let diffuse = self.diffuse.as_ref().map_or(1.0, |m| at(m)[3]);
        let alpha = self.alpha.as_ref().map_or(1.0, |(m, c)| c.of(at(m)));
        material.alpha() * diffuse * alpha
    }

    /// Whether the alpha test discards a point of alpha `alpha`.
    #[inline]
    pub fn discards(&self, alpha: f32) -> bool {
        self.alpha_cutoff.is_some_and(|c| alpha < c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Wrap;

    /// The normal stored at texel `(x, y)` (bottom row 0), decoded.
    fn stored(n: &NormalMap, x: u32, y: u32) -> glam::Vec3 {
        let t = n.map.texture.texel(0, x, y);
        glam::Vec3::new(t[0], t[1], t[2]) * 2.0 - 1.0
    }

    /// The alpha test's own sampling gives the alpha of the full sampling, bit for bit (the
    /// fast path's visibility and the reference's shading must discard the same points): a
    /// diffuse map with alpha on the first set, an alpha map's green on the second.
    #[test]
    fn alpha_sets_is_the_alpha_of_the_sampled_texels() {
        let texels: Vec<[u8; 4]> = (0..64u32)
            .map(|i| {
                [
                    (i * 37 % 256) as u8,
                    (i * 91 % 256) as u8,
                    (i * 13 % 256) as u8,
                    (i * 53 % 256) as u8,
                ]
            })
            .collect();
        let t = Arc::new(Texture::from_rgba8(8, 8, &texels).unwrap());
        let mut alpha = TextureMap::new(t.clone());
        alpha.set = 1;
        let maps = Maps {
            diffuse: Some(TextureMap::new(t)),
            alpha: Some((alpha, Channel::G)),
            ..Maps::default()
        };
        let material = Material::default().with_alpha(0.7).unwrap();
        for i in 0..200 {
            let f = i as f32;
            let first = [
                Vec2::new(f * 0.013, f * 0.029),
                Vec2::new(0.01 * (f % 7.0), 0.0),
                Vec2::new(0.0, 0.02 * (f % 5.0)),
            ];
            let second = [
                Vec2::new(f * 0.031, 1.0 - f * 0.007),
                Vec2::new(0.001, 0.0),
                Vec2::new(0.0, 0.3),
            ];
            let sets = [first, second];
            let full = Maps::alpha(&material, &maps.sample_sets(&sets));
            assert_eq!(maps.alpha_sets(&material, &sets).to_bits(), full.to_bits(), "point {i}");
        }
        // Without maps: the material's alpha.
        let none = Maps::default().alpha_sets(&material, &[[Vec2::ZERO; 3]; 2]);
        assert_eq!(none, 0.7);
    }

    #[test]
    fn bump_maps_become_the_normals_of_their_slopes() {
        // Heights 10·x + 30·y (bytes, in grey), y counted from the bottom row.
        let (w, h) = (6u32, 4u32);
        let top_first: Vec<[u8; 4]> = (0..h)
            .rev()
            .flat_map(|y| (0..w).map(move |x| [(10 * x + 30 * y) as u8; 3]))
            .map(|[r, g, b]| [r, g, b, 255])
            .collect();
        let height = Texture::from_rgba8(w, h, &top_first).unwrap();
        let k = 2.0;
        let n = NormalMap::from_height(
            &height,
            Channel::R,
            k,
            Sampler::bilinear(Wrap::Clamp),
            UvTransform::default(),
        )
        .unwrap();
        // Inside: ∂h/∂x = 10/255 and ∂h/∂y = 30/255 a texel.
        let inside = glam::Vec3::new(-k * 10.0 / 255.0, -k * 30.0 / 255.0, 1.0).normalize();
        // At a clamped edge the central difference spans one texel: half the slope.
        let edge = glam::Vec3::new(-k * 5.0 / 255.0, -k * 30.0 / 255.0, 1.0).normalize();
        for (x, y, want) in [(2, 1, inside), (3, 2, inside), (0, 1, edge), (5, 2, edge)] {
            let got = stored(&n, x, y);
            assert!(
                (got - want).abs().max_element() < 2.0 / 65535.0,
                "({x}, {y}): {got} vs {want}"
            );
        }
        // Repeat wraps: at x = 0 the left neighbour is x = 5, 50 higher.
        let r = NormalMap::from_height(
            &height,
            Channel::R,
            k,
            Sampler::bilinear(Wrap::Repeat),
            UvTransform::default(),
        )
        .unwrap();
        let want = glam::Vec3::new(-k * 0.5 * (10.0 - 50.0) / 255.0, -k * 30.0 / 255.0, 1.0).normalize();
        assert!((stored(&r, 0, 1) - want).abs().max_element() < 2.0 / 65535.0);
        assert!(!r.green_down && r.scale == 1.0);
    }
}
