//! Textures sampled as OpenGL samples them (the OpenGL 4.6 specification, §8.14): mipmaps
//! built once by 2×2 box filtering, the level of detail `λ = log2 ρ` from the screen-space
//! derivatives of the texture coordinates, texel centres at half-integers, repeat, clamp and
//! mirror wrapping, nearest, bilinear and trilinear filtering.
//!
//! Texels are kept in OpenGL's order: row 0 is the bottom of the image, so that `v = 0` is its
//! bottom edge as in OBJ's `vt` and OpenGL (glTF's `v` points down and is flipped by its reader).

use crate::Error;
use crate::limits::{MAX_TEXTURE_BYTES, MAX_TEXTURE_SIDE};
use glam::{Vec2, Vec4};
use std::ops::{Deref, Range};
use std::sync::Arc;

/// How a coordinate outside `[0, 1]` is brought back (`GL_REPEAT`, `GL_CLAMP_TO_EDGE`,
/// `GL_MIRRORED_REPEAT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The image repeats.
    #[default]
    Repeat,
    /// The edge texels extend outward.
    Clamp,
    /// The image repeats, every other copy mirrored.
    Mirror,
}

/// How texels are chosen within one level (`GL_NEAREST`, `GL_LINEAR`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    /// The texel containing the point.
    Nearest,
    /// The four nearest texels, weighted bilinearly.
    Linear,
}

/// How levels are chosen when minifying: none (level 0), the nearest level, or the two nearest
/// blended (`GL_*_MIPMAP_NEAREST`, `GL_*_MIPMAP_LINEAR`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MipFilter {
    /// Level 0 only.
    None,
    /// The nearest level.
    Nearest,
    /// The two nearest levels, blended by the fraction of `λ`.
    Linear,
}

/// A sampler's state, as OpenGL's texture parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampler {
    /// Wrapping of `u`.
    pub wrap_u: Wrap,
    /// Wrapping of `v`.
    pub wrap_v: Wrap,
    /// `GL_TEXTURE_MAG_FILTER`.
    pub mag: Filter,
    /// The texel filter of `GL_TEXTURE_MIN_FILTER`.
    pub min: Filter,
    /// The level filter of `GL_TEXTURE_MIN_FILTER`.
    pub mip: MipFilter,
}

impl Default for Sampler {
    /// Trilinear with repeat: `GL_LINEAR_MIPMAP_LINEAR`, `GL_LINEAR`, `GL_REPEAT`.
    fn default() -> Self {
        Sampler::trilinear(Wrap::Repeat)
    }
}

impl Sampler {
    /// `GL_LINEAR_MIPMAP_LINEAR` minification, `GL_LINEAR` magnification.
    pub fn trilinear(wrap: Wrap) -> Sampler {
        Sampler {
            wrap_u: wrap,
            wrap_v: wrap,
            mag: Filter::Linear,
            min: Filter::Linear,
            mip: MipFilter::Linear,
        }
    }
    /// `GL_LINEAR` both ways, no mipmaps.
    pub fn bilinear(wrap: Wrap) -> Sampler {
        Sampler {
            mip: MipFilter::None,
            ..Sampler::trilinear(wrap)
        }
    }
    /// `GL_NEAREST` both ways, no mipmaps.
    pub fn nearest(wrap: Wrap) -> Sampler {
        Sampler {
            wrap_u: wrap,
            wrap_v: wrap,
            mag: Filter::Nearest,
            min: Filter::Nearest,
            mip: MipFilter::None,
        }
    }

    /// The level of detail at which magnification ends (`c` of the specification, §8.14.2).
    fn switch_point(&self) -> f32 {
        if self.mag == Filter::Linear && self.min == Filter::Nearest && self.mip != MipFilter::None {
            0.5
        } else {
            0.0
        }
    }
}

/// A texel's storage: 8 or 16 bits a channel.
pub trait Texel: bytemuck::Pod + Send + Sync + std::fmt::Debug + PartialEq + 'static {
    /// The largest channel value (255 or 65535).
    const MAX: f32;
    /// The channels as values in `[0, 1]` (`c / 255` or `c / 65535`, correctly rounded).
    fn rgba(self) -> [f32; 4];
    /// The channels as they are stored, as floats.
    fn units(self) -> [f32; 4];
    /// The rounded mean of four texels (a mipmap's box filter).
    fn mean(t: [Self; 4]) -> Self;
    /// A row of the next level from rows `a` and `b` of this one, pairs of columns averaged
    /// ([`Texel::mean`] of each 2×2 block; an odd last column left out).
    fn halve_rows(a: &[Self], b: &[Self], out: &mut Vec<Self>);
    /// Whether alpha is below its maximum.
    fn translucent(self) -> bool;
}

/// [`Texel`] for RGBA of `$t` channels, `$wide` wide enough for the sum of four.
macro_rules! texel {
    ($t:ty, $wide:ty) => {
        impl Texel for [$t; 4] {
            const MAX: f32 = <$t>::MAX as f32;
            #[inline(always)]
            fn units(self) -> [f32; 4] {
                self.map(f32::from)
            }
            #[inline(always)]
            fn rgba(self) -> [f32; 4] {
                self.map(|c| f32::from(c) / Self::MAX)
            }
            #[inline(always)]
            fn mean(t: [Self; 4]) -> Self {
                std::array::from_fn(|i| {
                    let sum: $wide = t.iter().map(|x| <$wide>::from(x[i])).sum();
                    ((sum + 2) / 4) as $t
                })
            }
            fn halve_rows(a: &[Self], b: &[Self], out: &mut Vec<Self>) {
                // Flat channels, one output channel from four inputs 4 apart: a loop the
                // compiler vectorises (the per-texel `mean` did not).
                let n = a.len().min(b.len()) / 2;
                let (fa, fb) = (a[..2 * n].as_flattened(), b[..2 * n].as_flattened());
                let start = out.len();
                out.resize(start + n, [0; 4]);
                let dst = out[start..].as_flattened_mut();
                for ((d, p), q) in dst
                    .chunks_exact_mut(4)
                    .zip(fa.chunks_exact(8))
                    .zip(fb.chunks_exact(8))
                {
                    for c in 0..4 {
                        let sum = <$wide>::from(p[c])
                            + <$wide>::from(p[c + 4])
                            + <$wide>::from(q[c])
                            + <$wide>::from(q[c + 4]);
                        d[c] = ((sum + 2) / 4) as $t;
                    }
                }
            }
            fn translucent(self) -> bool {
                self[3] < <$t>::MAX
            }
        }
    };
}
texel!(u8, u16);
texel!(u16, u32);

/// Bytes that a texture's levels can be borrowed from instead of owned, such as a texture
/// cache's file read into memory (huge pages, which a `Vec` cannot ask for). It must give the
/// same bytes at every call.
pub type SharedBytes = Arc<dyn AsRef<[u8]> + Send + Sync>;

/// A level's texels: owned, or a checked range of shared bytes.
#[derive(Clone)]
enum Texels<T> {
    Owned(Vec<T>),
    Shared(SharedBytes, Range<usize>),
}

impl<T: Texel> Deref for Texels<T> {
    type Target = [T];
    #[inline(always)]
    fn deref(&self) -> &[T] {
        match self {
            Texels::Owned(v) => v,
            // The range's length and alignment were checked when it was made.
            Texels::Shared(bytes, r) => bytemuck::cast_slice(&(**bytes).as_ref()[r.clone()]),
        }
    }
}

impl<T: Texel> PartialEq for Texels<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T: Texel> std::fmt::Debug for Texels<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} texels", self.len())
    }
}

/// One mipmap level: `width × height` RGBA texels, bottom row first.
#[derive(Clone, Debug, PartialEq)]
struct Level<T: Texel> {
    width: u32,
    height: u32,
    texels: Texels<T>,
}

/// A mipmap chain of 8- or 16-bit texels.
#[derive(Clone, Debug, PartialEq)]
enum Chain {
    Eight(Vec<Level<[u8; 4]>>),
    Sixteen(Vec<Level<[u16; 4]>>),
}

/// An RGBA texture with its mipmap chain. Channels are linear values in `[0, 1]`, stored in 8
/// bits (an 8-bit source: byte `b` reads back as exactly `b/255`, as an `RGBA8` texture) or 16.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    chain: Chain,
    /// Whether a texel of level 0 has alpha below 1 (asked per pixel: found once).
    translucent: bool,
}

/// Checks a texture's size and its texel count.
fn check_size(width: u32, height: u32, texels: usize, bytes_per_texel: u64) -> Result<(), Error> {
    if width == 0 || height == 0 || width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
        return Err(Error::OutOfRange {
            what: "texture side",
            range: "between 1 and 16384 texels",
            value: width.max(height) as f32,
        });
    }
    let bytes = u64::from(width) * u64::from(height) * bytes_per_texel * 4 / 3;
    if bytes > MAX_TEXTURE_BYTES {
        return Err(Error::OutOfRange {
            what: "texture size with its mipmaps (bytes)",
            range: "at most 2 GiB",
            value: bytes as f32,
        });
    }
    if texels as u64 != u64::from(width) * u64::from(height) {
        return Err(Error::OutOfRange {
            what: "number of texels",
            range: "width × height",
            value: texels as f32,
        });
    }
    Ok(())
}

/// Level 0 from rows top first (turned over in place), then the chain down to 1×1.
fn chain<T: Texel>(width: u32, mut texels: Vec<T>) -> Vec<Level<T>> {
    let w = width as usize;
    let height = (texels.len() / w) as u32;
    let h = height as usize;
    for y in 0..h / 2 {
        let (top, bottom) = texels.split_at_mut((h - 1 - y) * w);
        top[y * w..(y + 1) * w].swap_with_slice(&mut bottom[..w]);
    }
    let mut levels = vec![Level {
        width,
        height,
        texels: Texels::Owned(texels),
    }];
    while let Some(next) = levels.last().and_then(Level::halved) {
        levels.push(next);
    }
    levels
}

/// Whether a texel has alpha below its maximum: blocks folded without a branch (vectorised;
/// `any` per texel was 13 ms on a 4096² image).
fn any_translucent<T: Texel>(texels: &[T]) -> bool {
    texels
        .chunks(4096)
        .any(|c| c.iter().fold(false, |a, t| a | t.translucent()))
}

/// A given mipmap chain as levels: level 0 within the limits, each next level its predecessor
/// halved, the last 1×1, every texel count matching its size.
fn checked_levels<T: Texel>(levels: Vec<(u32, u32, Texels<T>)>, bytes_per_texel: u64) -> Result<Vec<Level<T>>, Error> {
    let Some(&(w0, h0, ref t0)) = levels.first() else {
        return Err(Error::OutOfRange {
            what: "number of mipmap levels",
            range: "at least 1",
            value: 0.0,
        });
    };
    check_size(w0, h0, t0.len(), bytes_per_texel)?;
    let (mut w, mut h) = (w0, h0);
    for (i, (lw, lh, texels)) in levels.iter().enumerate() {
        if i > 0 {
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
        }
        if (*lw, *lh) != (w, h) || texels.len() as u64 != u64::from(w) * u64::from(h) {
            return Err(Error::OutOfRange {
                what: "mipmap level (its size or texel count)",
                range: "the level before it halved",
                value: i as f32,
            });
        }
    }
    if (w, h) != (1, 1) {
        return Err(Error::OutOfRange {
            what: "number of mipmap levels",
            range: "enough to reach 1×1",
            value: levels.len() as f32,
        });
    }
    Ok(levels
        .into_iter()
        .map(|(width, height, texels)| Level { width, height, texels })
        .collect())
}

/// Calls `$body` with `$l` bound to the chain's levels, whichever their storage.
macro_rules! with_levels {
    ($self:expr, $l:ident => $body:expr) => {
        match &$self.chain {
            Chain::Eight($l) => $body,
            Chain::Sixteen($l) => $body,
        }
    };
}

impl Texture {
    /// A texture from `width × height` texels of 16 bits a channel, **top row first** (as image
    /// files store them), whose source had `bits` (8 or 16) bits a channel: with 8, each value
    /// is taken as the byte `round(v / 257)` and stored in 8 bits. The mipmap chain is built
    /// down to 1×1: each texel of a level is the mean of the 2×2 block below it (the last row
    /// or column of an odd size is left out, as Mesa does), rounded to the storage's precision
    /// as a driver storing the source's format does.
    pub fn new(width: u32, height: u32, top_first: &[[u16; 4]], bits: u8) -> Result<Texture, Error> {
        if bits == 8 {
            let bytes: Vec<[u8; 4]> = top_first
                .iter()
                .map(|t| t.map(|c| ((u32::from(c) + 128) / 257) as u8))
                .collect();
            return Texture::from_rgba8(width, height, &bytes);
        }
        check_size(width, height, top_first.len(), 8)?;
        Ok(Texture {
            chain: Chain::Sixteen(chain(width, top_first.to_vec())),
            translucent: any_translucent(top_first),
        })
    }

    /// A texture from 8-bit texels, top row first (see [`Texture::new`]).
    pub fn from_rgba8(width: u32, height: u32, top_first: &[[u8; 4]]) -> Result<Texture, Error> {
        check_size(width, height, top_first.len(), 4)?;
        Texture::from_rgba8_vec(width, height, top_first.to_vec())
    }

    /// [`Texture::from_rgba8`] taking the texels' vector, which becomes level 0 (no copy).
    pub fn from_rgba8_vec(width: u32, height: u32, top_first: Vec<[u8; 4]>) -> Result<Texture, Error> {
        check_size(width, height, top_first.len(), 4)?;
        let translucent = any_translucent(&top_first);
        Ok(Texture {
            chain: Chain::Eight(chain(width, top_first)),
            translucent,
        })
    }

    /// A texture from a whole mipmap chain of 8-bit texels as [`Texture::level8`] gives it
    /// (bottom row first), such as a cache kept: checked, not rebuilt. Each level must be the
    /// one before halved (rounded down, at least 1) down to 1×1, with its texel count.
    pub fn from_levels8(levels: Vec<(u32, u32, Vec<[u8; 4]>)>) -> Result<Texture, Error> {
        Texture::from_levels(levels, 4, Chain::Eight)
    }

    /// [`Texture::from_levels8`] for 16-bit texels ([`Texture::level16`]).
    pub fn from_levels16(levels: Vec<(u32, u32, Vec<[u16; 4]>)>) -> Result<Texture, Error> {
        Texture::from_levels(levels, 8, Chain::Sixteen)
    }

    /// A texture from a whole mipmap chain of 8-bit texels of sizes `sizes`, borrowed from
    /// `bytes`, which holds the levels end to end from byte 0 (as [`Texture::from_levels8`]
    /// takes them) and nothing after them. `has_alpha`: [`Texture::has_alpha`] where the caller
    /// knows it, else found from the texels.
    pub fn from_shared8(bytes: SharedBytes, sizes: &[(u32, u32)], has_alpha: Option<bool>) -> Result<Texture, Error> {
        Texture::from_shared(bytes, sizes, has_alpha, 4, Chain::Eight)
    }

    /// [`Texture::from_shared8`] for 16-bit texels (2-byte aligned).
    pub fn from_shared16(bytes: SharedBytes, sizes: &[(u32, u32)], has_alpha: Option<bool>) -> Result<Texture, Error> {
        Texture::from_shared(bytes, sizes, has_alpha, 8, Chain::Sixteen)
    }

    fn from_shared<T: Texel>(
        bytes: SharedBytes,
        sizes: &[(u32, u32)],
        has_alpha: Option<bool>,
        bytes_per_texel: u64,
        chain: fn(Vec<Level<T>>) -> Chain,
    ) -> Result<Texture, Error> {
        let all = (*bytes).as_ref();
        let mut at = 0usize;
        let mut levels = Vec::with_capacity(sizes.len());
        for &(w, h) in sizes {
            let len = (u64::from(w) * u64::from(h)).saturating_mul(bytes_per_texel);
            let end = usize::try_from(len).ok().and_then(|len| at.checked_add(len));
            let range = end.filter(|&end| end <= all.len()).map(|end| at..end);
            let Some(range) = range.filter(|r| bytemuck::try_cast_slice::<u8, T>(&all[r.clone()]).is_ok()) else {
                return Err(Error::OutOfRange {
                    what: "shared texel bytes (their length or alignment)",
                    range: "the levels' sizes, end to end",
                    value: levels.len() as f32,
                });
            };
            at = range.end;
            levels.push((w, h, Texels::Shared(bytes.clone(), range)));
        }
        if at != all.len() {
            return Err(Error::OutOfRange {
                what: "shared texel bytes (their length)",
                range: "the levels' sizes, end to end",
                value: all.len() as f32,
            });
        }
        Texture::checked(levels, has_alpha, bytes_per_texel, chain)
    }

    fn from_levels<T: Texel>(
        levels: Vec<(u32, u32, Vec<T>)>,
        bytes_per_texel: u64,
        chain: fn(Vec<Level<T>>) -> Chain,
    ) -> Result<Texture, Error> {
        let levels = levels.into_iter().map(|(w, h, t)| (w, h, Texels::Owned(t))).collect();
        Texture::checked(levels, None, bytes_per_texel, chain)
    }

    fn checked<T: Texel>(
        levels: Vec<(u32, u32, Texels<T>)>,
        has_alpha: Option<bool>,
        bytes_per_texel: u64,
        chain: fn(Vec<Level<T>>) -> Chain,
    ) -> Result<Texture, Error> {
        let levels = checked_levels(levels, bytes_per_texel)?;
        let translucent = has_alpha.unwrap_or_else(|| any_translucent(&levels[0].texels));
        Ok(Texture {
            chain: chain(levels),
            translucent,
        })
    }

    /// Width of level 0.
    pub fn width(&self) -> u32 {
        with_levels!(self, l => l[0].width)
    }
    /// Height of level 0.
    pub fn height(&self) -> u32 {
        with_levels!(self, l => l[0].height)
    }
    /// Bits a channel (8 or 16).
    pub fn bits(&self) -> u8 {
        match self.chain {
            Chain::Eight(_) => 8,
            Chain::Sixteen(_) => 16,
        }
    }
    /// Number of mipmap levels (level 0 included).
    pub fn level_count(&self) -> usize {
        with_levels!(self, l => l.len())
    }
    /// Level `i` of an 8-bit texture: its size and texels, bottom row first.
    pub fn level8(&self, i: usize) -> Option<(u32, u32, &[[u8; 4]])> {
        match &self.chain {
            Chain::Eight(l) => Some((l[i].width, l[i].height, &l[i].texels)),
            Chain::Sixteen(_) => None,
        }
    }
    /// Level `i` of a 16-bit texture: its size and texels, bottom row first.
    pub fn level16(&self, i: usize) -> Option<(u32, u32, &[[u16; 4]])> {
        match &self.chain {
            Chain::Sixteen(l) => Some((l[i].width, l[i].height, &l[i].texels)),
            Chain::Eight(_) => None,
        }
    }
    /// Bytes held, every level.
    pub fn bytes(&self) -> u64 {
        with_levels!(self, l => l.iter().map(|l| (l.texels.len() * size_of_val(&l.texels[0])) as u64).sum())
    }
    /// Whether any texel of level 0 has alpha below 1.
    pub fn has_alpha(&self) -> bool {
        self.translucent
    }

    /// Texel `(x, y)` of `level` (bottom row 0) as linear RGBA.
    #[inline]
    pub fn texel(&self, level: usize, x: u32, y: u32) -> [f32; 4] {
        with_levels!(self, l => l[level].texel(x, y))
    }

    /// The level of detail `λ = log2 ρ` for texture-coordinate derivatives `d(u, v)/dx` and
    /// `d(u, v)/dy` (per pixel): `ρ = max(|(∂u/∂x·w, ∂v/∂x·h)|, |(∂u/∂y·w, ∂v/∂y·h)|)`, the
    /// specification's equation 8.7 with `w`, `h` the size of level 0.
    #[inline]
    pub fn lod(&self, d_dx: Vec2, d_dy: Vec2) -> f32 {
        let size = Vec2::new(self.width() as f32, self.height() as f32);
        // log2 ρ = ½ log2 ρ²: no square roots.
        let rho2 = (d_dx * size).length_squared().max((d_dy * size).length_squared());
        0.5 * log2(rho2)
    }

    /// The filtered RGBA at `uv` with level of detail `lod` (see [`Texture::lod`]), as OpenGL's
    /// sampler `s` gives it. A NaN level of detail magnifies.
    pub fn sample(&self, s: &Sampler, uv: Vec2, lod: f32) -> [f32; 4] {
        with_levels!(self, l => sample_levels(l, s, uv, lod))
    }
}

/// [`Texture::sample`] on one storage's levels.
#[inline(always)]
fn sample_levels<T: Texel>(levels: &[Level<T>], s: &Sampler, uv: Vec2, lod: f32) -> [f32; 4] {
    let filter = |level: usize, f: Filter| levels[level].filter(f, s, uv);
    {
        let minify = lod > s.switch_point();
        if !minify {
            return filter(0, s.mag);
        }
        let q = (levels.len() - 1) as f32;
        match s.mip {
            MipFilter::None => filter(0, s.min),
            MipFilter::Nearest => {
                let d = if lod <= 0.5 {
                    0.0
                } else {
                    ((lod + 0.5).ceil() - 1.0).min(q)
                };
                filter(d as usize, s.min)
            }
            MipFilter::Linear => {
                if lod >= q {
                    return filter(q as usize, s.min);
                }
                let d1 = floor(lod);
                let t = lod - d1;
                let a = filter(d1 as usize, s.min);
                let b = filter(d1 as usize + 1, s.min);
                std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
            }
        }
    }
}

impl Texture {}

impl<T: Texel> Level<T> {
    #[inline(always)]
    fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        self.texels[y as usize * self.width as usize + x as usize].rgba()
    }

    /// Texel `(x, y)` in its storage's units (0 to 255 or 65535).
    #[inline(always)]
    fn raw(&self, x: u32, y: u32) -> Vec4 {
        Vec4::from_array(self.texels[y as usize * self.width as usize + x as usize].units())
    }

    /// `uv` filtered within this level.
    #[inline(always)]
    fn filter(&self, f: Filter, s: &Sampler, uv: Vec2) -> [f32; 4] {
        let (w, h) = (self.width as f32, self.height as f32);
        match f {
            Filter::Nearest => {
                let x = wrap(s.wrap_u, floor(uv.x * w), self.width);
                let y = wrap(s.wrap_v, floor(uv.y * h), self.height);
                self.texel(x, y)
            }
            Filter::Linear => {
                let (fx, fy) = (uv.x * w - 0.5, uv.y * h - 0.5);
                let (ix, iy) = (floor(fx), floor(fy));
                let (a, b) = (fx - ix, fy - iy);
                let (x0, x1) = wrap_pair(s.wrap_u, ix, self.width);
                let (y0, y1) = wrap_pair(s.wrap_v, iy, self.height);
                // Four channels at once (glam's SSE vectors), in the storage's units, scaled to
                // [0, 1] once.
                let t00 = self.raw(x0, y0);
                let t10 = self.raw(x1, y0);
                let t01 = self.raw(x0, y1);
                let t11 = self.raw(x1, y1);
                let (w00, w10) = ((1.0 - a) * (1.0 - b), a * (1.0 - b));
                let (w01, w11) = ((1.0 - a) * b, a * b);
                ((t00 * w00 + t10 * w10 + t01 * w01 + t11 * w11) / T::MAX).to_array()
            }
        }
    }

    /// The next mipmap level, `None` at 1×1.
    fn halved(&self) -> Option<Level<T>> {
        if self.width == 1 && self.height == 1 {
            return None;
        }
        let (width, height) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let sw = self.width as usize;
        let step = |n: u32| usize::from(n > 1);
        let (dx, dy) = (step(self.width), step(self.height));
        let mut texels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height as usize {
            let (ya, yb) = (y * (1 + dy), y * (1 + dy) + dy);
            let (a, b) = (&self.texels[ya * sw..][..sw], &self.texels[yb * sw..][..sw]);
            if dx == 1 {
                // Pairs of columns (an odd last column is left out).
                T::halve_rows(a, b, &mut texels);
            } else {
                texels.extend(a.iter().zip(b).map(|(&p, &q)| T::mean([p, p, q, q])));
            }
        }
        Some(Level {
            width,
            height,
            texels: Texels::Owned(texels),
        })
    }
}

/// `log2 x` within 2·10⁻⁵ (the level of detail needs no more: OpenGL allows an approximation,
/// and a blend weight off by 10⁻⁵ is 0.003/255), without libm's call: the exponent, plus a
/// degree-5 least-squares polynomial in the mantissa. 0 gives −∞, NaN and negatives NaN.
#[inline(always)]
fn log2(x: f32) -> f32 {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32;
    if x.is_nan() || x <= 0.0 || e == 0 || e == 0xff {
        // Zero, negative, NaN, subnormal or infinite: rare, exact.
        return x.log2();
    }
    let t = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000) - 1.0;
    let p = t * (1.441_879_9 + t * (-0.708_865_2 + t * (0.415_245_56 + t * (-0.193_516_53 + t * 0.045_268_293))));
    (e - 127) as f32 + p
}

/// `x.floor()` without a call to libm's `floorf` (x86-64's baseline has no rounding
/// instruction): by truncation where `x` is exact in `i32`, else `floor`.
#[inline(always)]
fn floor(x: f32) -> f32 {
    if x.abs() < 8_388_608.0 {
        let t = x as i32 as f32;
        if t > x { t - 1.0 } else { t }
    } else {
        x.floor()
    }
}

/// `wrap(i)` and `wrap(i + 1)`: the two texels a bilinear filter reads along one axis.
#[inline(always)]
fn wrap_pair(mode: Wrap, i: f32, n: u32) -> (u32, u32) {
    let a = wrap(mode, i, n);
    match mode {
        Wrap::Repeat => (a, if a + 1 == n { 0 } else { a + 1 }),
        _ => (a, wrap(mode, i + 1.0, n)),
    }
}

/// Integer texel coordinate `i` (a whole number as `f32`, any size; NaN is 0) wrapped into
/// `0..n`.
#[inline(always)]
fn wrap(mode: Wrap, i: f32, n: u32) -> u32 {
    let nf = n as f32;
    // Inside the image, or a few copies away (exact in f32 below 2^23): no integer division.
    if (0.0..nf).contains(&i) {
        return i as u32;
    }
    if mode == Wrap::Repeat && i.abs() < 8_388_608.0 {
        // Whole numbers, exact in f32; the quotient's rounding can leave `r` one period out.
        let mut r = i - nf * floor(i / nf);
        if r < 0.0 {
            r += nf;
        } else if r >= nf {
            r -= nf;
        }
        return (r as u32).min(n - 1);
    }
    let i = i as i64;
    let n = i64::from(n);
    let k = match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let p = i.rem_euclid(2 * n);
            if p < n { p } else { 2 * n - 1 - p }
        }
    };
    k as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: &[u8], w: u32, h: u32) -> Texture {
        let t: Vec<[u16; 4]> = v.iter().map(|&b| [u16::from(b) * 257; 4]).collect();
        Texture::new(w, h, &t, 8).unwrap()
    }

    #[test]
    fn a_chain_given_whole_is_kept_and_a_wrong_one_refused() {
        // 3×2 → 1×1, as `mipmaps_are_rounded_box_means_down_to_one_texel` builds it.
        let t = grey(&[0, 10, 99, 20, 31, 99], 3, 2);
        let levels = |t: &Texture| -> Vec<(u32, u32, Vec<[u8; 4]>)> {
            (0..t.level_count())
                .map(|i| t.level8(i).map(|(w, h, x)| (w, h, x.to_vec())).unwrap())
                .collect()
        };
        assert_eq!(Texture::from_levels8(levels(&t)).unwrap(), t);
        // A level missing, a wrong size, a short level, no level: errors.
        let mut short = levels(&t);
        short.pop();
        assert!(Texture::from_levels8(short).is_err());
        let mut wrong = levels(&t);
        wrong[1].0 = 2;
        assert!(Texture::from_levels8(wrong).is_err());
        let mut cut = levels(&t);
        cut[0].2.pop();
        assert!(Texture::from_levels8(cut).is_err());
        assert!(Texture::from_levels16(Vec::new()).is_err());
        // 16 bits, translucency found from level 0.
        let t16 = Texture::new(1, 2, &[[0, 0, 0, 65535], [9, 9, 9, 100]], 16).unwrap();
        let l16: Vec<_> = (0..t16.level_count())
            .map(|i| t16.level16(i).map(|(w, h, x)| (w, h, x.to_vec())).unwrap())
            .collect();
        let back = Texture::from_levels16(l16).unwrap();
        assert!(back.has_alpha());
        assert_eq!(back, t16);
    }

    #[test]
    fn levels_borrowed_from_shared_bytes_sample_as_owned_ones() {
        let t = grey(&[0, 10, 99, 20, 31, 99], 3, 2);
        let flat: Vec<u8> = (0..t.level_count())
            .flat_map(|i| t.level8(i).unwrap().2.as_flattened().to_vec())
            .collect();
        let sizes = [(3, 2), (1, 1)];
        let shared = Texture::from_shared8(Arc::new(flat.clone()), &sizes, None).unwrap();
        assert_eq!(shared, t);
        assert!(shared.has_alpha(), "grey's alpha is its value: found from the texels");
        let s = Sampler::trilinear(Wrap::Repeat);
        for (uv, lod) in [
            (Vec2::new(0.3, 0.7), 0.0),
            (Vec2::new(0.9, 0.2), 0.4),
            (Vec2::new(-0.6, 1.3), 2.0),
        ] {
            assert_eq!(shared.sample(&s, uv, lod), t.sample(&s, uv, lod));
        }
        // A caller that knows the alpha is believed; one that does not has it found.
        assert!(
            !Texture::from_shared8(Arc::new(flat.clone()), &sizes, Some(false))
                .unwrap()
                .has_alpha()
        );
        // Too few bytes, one too many, a chain that is not halved: errors.
        assert!(Texture::from_shared8(Arc::new(flat[..27].to_vec()), &sizes, None).is_err());
        assert!(Texture::from_shared8(Arc::new([&flat[..], &[0]].concat()), &sizes, None).is_err());
        assert!(Texture::from_shared8(Arc::new(flat.clone()), &[(3, 2), (2, 1)], None).is_err());
        // 16 bits need 2-byte alignment: bytes that start at an odd address are refused.
        let t16 = Texture::new(1, 2, &[[0, 0, 0, 65535], [9, 9, 9, 100]], 16).unwrap();
        let mut b16: Vec<u8> = vec![0];
        for i in 0..t16.level_count() {
            b16.extend_from_slice(bytemuck::cast_slice(t16.level16(i).unwrap().2));
        }
        let odd = OddStart(b16);
        let even = Arc::new(odd.as_ref()[..].to_vec());
        let sizes16 = [(1, 2), (1, 1)];
        let aligned = Texture::from_shared16(even, &sizes16, None);
        let unaligned = Texture::from_shared16(Arc::new(odd), &sizes16, None);
        assert_eq!(aligned.unwrap(), t16);
        assert!(unaligned.is_err());
    }

    /// Bytes one past the start of a vector (whose buffer the allocator aligns): an odd address.
    struct OddStart(Vec<u8>);
    impl AsRef<[u8]> for OddStart {
        fn as_ref(&self) -> &[u8] {
            &self.0[1..]
        }
    }

    #[test]
    fn mipmaps_are_rounded_box_means_down_to_one_texel() {
        // 3×2, top row first: [0 10 99; 20 31 99]; bottom-first rows [20 31 99], [0 10 99].
        let t = grey(&[0, 10, 99, 20, 31, 99], 3, 2);
        assert_eq!(t.level_count(), 2);
        let (w, h, l1) = t.level8(1).unwrap();
        assert_eq!((w, h), (1, 1));
        // The odd column is left out: (0 + 10 + 20 + 31) / 4 = 15.25 → 15.
        assert_eq!(l1[0][0], 15);
        assert_eq!(t.texel(0, 0, 1)[0], 0.0, "row 1 is the image's top row");
        assert_eq!(t.texel(0, 1, 0)[0], 31.0 / 255.0);
        // An odd number of rows, turned over in place: the middle one stays.
        let t = grey(&[10, 20, 30, 40, 50, 60], 2, 3);
        let rows: Vec<[f32; 2]> = (0..3).map(|y| [t.texel(0, 0, y)[0], t.texel(0, 1, y)[0]]).collect();
        assert_eq!(
            rows,
            [[50.0, 60.0], [30.0, 40.0], [10.0, 20.0]].map(|r| r.map(|v| v / 255.0))
        );
    }

    #[test]
    fn wrap_modes_follow_the_specification() {
        let n = 4;
        let r: Vec<u32> = (-5..6).map(|i| wrap(Wrap::Repeat, i as f32, n)).collect();
        assert_eq!(r, [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1]);
        let c: Vec<u32> = (-2..6).map(|i| wrap(Wrap::Clamp, i as f32, n)).collect();
        assert_eq!(c, [0, 0, 0, 1, 2, 3, 3, 3]);
        let m: Vec<u32> = (-5..9).map(|i| wrap(Wrap::Mirror, i as f32, n)).collect();
        assert_eq!(m, [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]);
        assert_eq!(wrap(Wrap::Repeat, f32::NAN, n), 0);
        // The f32 shortcut against integer arithmetic, near and far, every size.
        let mut x = 12345u64;
        for _ in 0..200_000 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let n = 1 + (x >> 33) as u32 % 5000;
            let i = ((x >> 7) % 40_000_000) as i64 - 20_000_000;
            // The coordinate as the sampler has it (f32: past 2^24, every other integer).
            let i = i as f32 as i64;
            let want = i.rem_euclid(i64::from(n)) as u32;
            assert_eq!(wrap(Wrap::Repeat, i as f32, n), want, "{i} mod {n}");
            let (a, b) = wrap_pair(Wrap::Repeat, i as f32, n);
            assert_eq!((a, b), (want, (want + 1) % n), "{i} mod {n}");
        }
        assert!(wrap(Wrap::Mirror, 1e30, n) < n);
    }

    #[test]
    fn bilinear_weights_texel_centres_at_half_integers() {
        // 2×1: left 0, right 255 (bottom row = the only row).
        let t = grey(&[0, 255], 2, 1);
        let s = Sampler::bilinear(Wrap::Clamp);
        // u = 0.25 is the left texel's centre, 0.75 the right one's, 0.5 halfway.
        assert_eq!(t.sample(&s, Vec2::new(0.25, 0.5), -1.0)[0], 0.0);
        assert_eq!(t.sample(&s, Vec2::new(0.75, 0.5), -1.0)[0], 1.0);
        assert!((t.sample(&s, Vec2::new(0.5, 0.5), -1.0)[0] - 0.5).abs() < 1e-6);
        assert!((t.sample(&s, Vec2::new(0.375, 0.5), -1.0)[0] - 0.25).abs() < 1e-6);
        // Repeat blends the right edge with the left texel.
        let r = Sampler::bilinear(Wrap::Repeat);
        assert!((t.sample(&r, Vec2::new(1.0, 0.5), -1.0)[0] - 0.5).abs() < 1e-6);
    }

    #[test]
    fn trilinear_blends_levels_by_the_fraction_of_lod() {
        // 2×2 of 0, 0, 255, 255: level 1 is 128 (127.5 rounded half away from zero).
        let t = grey(&[0, 0, 255, 255], 2, 2);
        let s = Sampler::trilinear(Wrap::Clamp);
        let uv = Vec2::new(0.25, 0.25); // the bottom-left texel's centre: 255 (bottom row)
        assert_eq!(t.sample(&s, uv, 0.0)[0], 1.0, "λ = 0 magnifies");
        let l1 = 128.0 / 255.0;
        assert_eq!(t.sample(&s, uv, 1.0)[0], l1);
        assert_eq!(t.sample(&s, uv, 7.0)[0], l1, "past the last level");
        let mid = t.sample(&s, uv, 0.25)[0];
        assert!((mid - (1.0 + (l1 - 1.0) * 0.25)).abs() < 1e-6, "{mid}");
        // Nearest-mipmap picks level 1 from λ > 0.5.
        let n = Sampler {
            mip: MipFilter::Nearest,
            ..s
        };
        assert_eq!(t.sample(&n, uv, 0.4)[0], 1.0);
        assert_eq!(t.sample(&n, uv, 0.6)[0], l1);
    }

    #[test]
    fn log2_is_within_2e_5() {
        let mut x = 1e-30f32;
        while x < 1e30 {
            for k in 0..50 {
                let v = x * (1.0 + k as f32 / 50.0);
                assert!((log2(v) - v.log2()).abs() < 2e-5, "{v}: {} vs {}", log2(v), v.log2());
            }
            x *= 2.0;
        }
        assert_eq!(log2(0.0), f32::NEG_INFINITY);
        assert!(log2(f32::NAN).is_nan() && log2(-1.0).is_nan());
        assert_eq!(log2(f32::INFINITY), f32::INFINITY);
        assert_eq!(log2(1.0), 0.0);
    }

    #[test]
    fn lod_is_log2_of_the_longer_footprint() {
        let t = grey(&[0; 64 * 32], 64, 32);
        // One pixel covers 1/16 of u: 4 texels; and 1/8 of v: 4 texels.
        let lod = t.lod(Vec2::new(1.0 / 16.0, 0.0), Vec2::new(0.0, 1.0 / 8.0));
        assert!((lod - 2.0).abs() < 1e-6);
        let lod = t.lod(Vec2::new(1.0 / 64.0, 1.0 / 32.0), Vec2::ZERO);
        assert!((lod - 0.5).abs() < 1e-6, "ρ = √2: {lod}");
    }

    #[test]
    fn sizes_past_the_limits_are_errors() {
        assert!(Texture::new(0, 1, &[], 8).is_err());
        assert!(Texture::new(MAX_TEXTURE_SIDE + 1, 1, &[], 8).is_err());
        assert!(Texture::new(2, 2, &[[0; 4]; 3], 8).is_err());
    }
}
