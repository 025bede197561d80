//! Texture maps as files name them: images decoded (the `image` crate: PNG, JPEG, TGA, BMP;
//! 8 and 16 bits, grey, grey and alpha, RGB, RGBA, palette), MTL map statements and their
//! options, and a material's requests turned into phong-core's [`Maps`].
//!
//! A map whose image is missing or cannot be decoded is a warning naming the material, the
//! file and why; the material is drawn without it (as three.js does).

use crate::texture_store::{self, Key};
use phong_core::limits::{MAX_IMAGE_FILE_BYTES, MAX_TEXTURE_BYTES, MAX_TEXTURE_SIDE};
use phong_core::{Channel, Maps, MetalRough, NormalMap, Occlusion, Sampler, Texture, TextureMap, UvTransform, Wrap};
use std::cell::Cell;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

/// What reading texture images cost: images decoded, bytes held with their mipmaps, and the
/// time decoding and building mipmaps (for `-v`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TextureStats {
    /// Images decoded.
    pub images: usize,
    /// Bytes of their textures, mipmaps included.
    pub bytes: u64,
    /// Reading the image files.
    pub read: Duration,
    /// Hashing and decoding the images, or reading them back from the texture store.
    pub decode: Duration,
    /// Building the mipmap chains.
    pub mipmaps: Duration,
    /// Images read back from the texture store (their time is in `decode`).
    pub from_store: usize,
    /// Writing decoded textures to the store.
    pub store_writes: Duration,
    /// Writes to the store that failed (see [`last_store_error`]).
    pub store_failures: usize,
    /// Images another load of this process had decoded, shared (not in `images`).
    pub shared: usize,
}

static STORE_ERROR: Mutex<Option<String>> = Mutex::new(None);

/// Why the last write to the texture store failed, if one did.
pub fn last_store_error() -> Option<String> {
    STORE_ERROR.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

thread_local! {
    /// This thread's texture reading since [`take_stats`]: loading a scene is one call on one
    /// thread, and its loaders (scene keys, OBJ, glTF) each keep their own cache.
    static STATS: Cell<TextureStats> = Cell::new(TextureStats::default());
}

/// The texture reading done on this thread since the last call, and a fresh count.
pub fn take_stats() -> TextureStats {
    STATS.with(|s| s.replace(TextureStats::default()))
}

thread_local! {
    /// Bytes of textures the load under way on this thread may still decode (`None`: no load
    /// keeps count; each texture is still held to its own limit).
    static BUDGET: Cell<Option<u64>> = const { Cell::new(None) };
}

/// One scene's texture memory, mipmaps included, held to `MAX_TEXTURE_BYTES` across all its
/// loaders (scene keys, OBJs, glTFs): the loaders' entry points hold one while they read; a
/// nested one (a scene's model) shares the outer one's count.
pub(crate) struct TextureBudget {
    owner: bool,
}

impl TextureBudget {
    /// Counts this thread's textures from here until it is dropped (unless a count is running).
    pub(crate) fn start() -> TextureBudget {
        TextureBudget::with_limit(MAX_TEXTURE_BYTES)
    }

    fn with_limit(limit: u64) -> TextureBudget {
        let owner = BUDGET.with(|b| b.get().is_none());
        if owner {
            BUDGET.with(|b| b.set(Some(limit)));
        }
        TextureBudget { owner }
    }
}

impl Drop for TextureBudget {
    fn drop(&mut self) {
        if self.owner {
            BUDGET.with(|b| b.set(None));
        }
    }
}

/// Takes `bytes` from the running count; an error where they do not fit.
fn spend(bytes: u64) -> Result<(), String> {
    BUDGET.with(|b| match b.get() {
        Some(left) if bytes > left => Err(format!(
            "the scene's textures would pass {} MiB with its {} MiB (MAX_TEXTURE_BYTES counts them all, mipmaps included)",
            MAX_TEXTURE_BYTES >> 20,
            bytes >> 20
        )),
        Some(left) => {
            b.set(Some(left - bytes));
            Ok(())
        }
        None => Ok(()),
    })
}

/// Which map of a material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// `map_Kd`, `diffuse_map`, glTF's base colour texture.
    Diffuse,
    /// `map_Ka`, `ambient_map`.
    Ambient,
    /// `map_Ks`, `specular_map`.
    Specular,
    /// `map_Ke`, `emission_map`, glTF's emissive texture.
    Emission,
    /// `map_Ns`, `shininess_map`.
    Shininess,
    /// `map_d`, `alpha_map`.
    Alpha,
    /// `bump`, `map_Bump`, `bump_map`: a height map.
    Bump,
    /// `norm`, `normal_map`, glTF's normal texture: a tangent-space normal map.
    Normal,
    /// glTF's metallic-roughness texture (its factors are the loader's to set).
    MetalRough,
    /// glTF's occlusion texture.
    Occlusion,
}

impl Slot {
    /// Colour maps are decoded from sRGB where the material asks; data maps never are.
    fn is_colour(self) -> bool {
        matches!(self, Slot::Diffuse | Slot::Ambient | Slot::Specular | Slot::Emission)
    }
}

/// Where a texture's bytes come from.
#[derive(Clone, Debug)]
pub enum Source {
    /// A file name as the MTL, scene or glTF gives it, read by the loader's reader.
    File(String),
    /// Bytes embedded in the model (a glTF data URI or buffer view), named for messages.
    Bytes(Arc<Vec<u8>>, String),
}

impl Source {
    fn name(&self) -> &str {
        match self {
            Source::File(f) => f,
            Source::Bytes(_, name) => name,
        }
    }
}

/// A map a material asks for, before its image is read.
#[derive(Clone, Debug)]
pub struct MapRequest {
    /// Which map.
    pub slot: Slot,
    /// The image.
    pub source: Source,
    /// Applied to the mesh's coordinates.
    pub transform: UvTransform,
    /// Sampler (wrap and filters).
    pub sampler: Sampler,
    /// The channel of a scalar map (`None`: the default, see [`resolve`]).
    pub channel: Option<Channel>,
    /// Decode a colour map from sRGB.
    pub srgb: bool,
    /// Where the request is, for messages (`file.mtl:12`, `scene.toml: materials.brick`).
    pub at: String,
    /// A normal map: the scale of its tangential components; a bump map: its multiplier
    /// (`-bm`, `bump_scale`); an occlusion map: its strength. 1 by default.
    pub scale: f32,
    /// A normal map: green along `−v` (DirectX's convention).
    pub green_down: bool,
    /// The mesh's texture coordinates the map reads ([`TextureMap::set`]).
    pub set: u8,
}

/// Decoded textures by (name, sRGB), so that a file named by several materials is read once.
#[derive(Default)]
pub struct TextureCache {
    done: HashMap<ImageKey, Result<Arc<Texture>, String>>,
    /// Decoded ahead by [`TextureCache::prefetch`], not yet counted against the budget.
    ready: HashMap<ImageKey, Result<Arc<Texture>, String>>,
}

/// An image as maps name it: its name, and whether it is decoded from sRGB.
type ImageKey = (String, bool);

/// Reads a file named by a map (the name as written; the reader resolves it).
pub type ReadFile<'a> = dyn Fn(&str) -> Result<Vec<u8>, String> + 'a;

impl TextureCache {
    fn load(&mut self, source: &Source, srgb: bool, read: &ReadFile) -> Result<Arc<Texture>, String> {
        let key = (source.name().to_string(), srgb);
        if let Some(r) = self.done.get(&key) {
            return r.clone();
        }
        let decoded = match self.ready.remove(&key) {
            Some(r) => r,
            None => {
                let mut stats = TextureStats::default();
                let begun = Instant::now();
                let bytes = read_source(source, read);
                stats.read = begun.elapsed();
                let r = bytes.and_then(|b| shared_or_decoded(&b, srgb, Instant::now(), &mut stats));
                add_stats(&stats);
                r
            }
        };
        // The budget is spent in the order the maps are used, wherever they were decoded.
        let r = decoded.and_then(|t| spend(t.bytes()).map(|()| t));
        self.done.insert(key, r.clone());
        r
    }

    /// Reads the images `requests` will load that are not loaded yet (on this thread, through
    /// `read`), then decodes them on all cores: a material's maps, or a model's, decode side
    /// by side instead of one after another.
    fn prefetch<'r>(&mut self, requests: impl IntoIterator<Item = &'r MapRequest>, read: &ReadFile) {
        let mut wanted: Vec<(ImageKey, Result<Vec<u8>, String>)> = Vec::new();
        let begun = Instant::now();
        for r in requests {
            let key = (r.source.name().to_string(), r.srgb && r.slot.is_colour());
            if self.done.contains_key(&key) || self.ready.contains_key(&key) || wanted.iter().any(|(k, _)| *k == key) {
                continue;
            }
            wanted.push((key, read_source(&r.source, read)));
        }
        add_stats(&TextureStats {
            read: begun.elapsed(),
            ..TextureStats::default()
        });
        if wanted.is_empty() {
            return;
        }
        let threads = crate::beside::cores().min(wanted.len());
        let results = crate::beside::map(
            wanted.iter().map(|(key, bytes)| (key.1, bytes)).collect(),
            threads,
            |(srgb, bytes)| {
                let mut stats = TextureStats::default();
                let r = match bytes {
                    Ok(b) => shared_or_decoded(b, srgb, Instant::now(), &mut stats),
                    Err(e) => Err(e.clone()),
                };
                (r, stats)
            },
        );
        for ((key, _), (r, stats)) in wanted.into_iter().zip(results) {
            add_stats(&stats);
            self.ready.insert(key, r);
        }
    }
}

/// The bytes of a map's image.
fn read_source(source: &Source, read: &ReadFile) -> Result<Vec<u8>, String> {
    match source {
        Source::File(f) => read(f),
        Source::Bytes(b, _) => Ok(b.to_vec()),
    }
}

/// Adds `stats` to this thread's.
fn add_stats(stats: &TextureStats) {
    STATS.with(|s| {
        let mut v = s.get();
        v.images += stats.images;
        v.bytes += stats.bytes;
        v.read += stats.read;
        v.decode += stats.decode;
        v.mipmaps += stats.mipmaps;
        v.from_store += stats.from_store;
        v.store_writes += stats.store_writes;
        v.store_failures += stats.store_failures;
        v.shared += stats.shared;
        s.set(v);
    });
}

/// Textures alive in this process by their image's [`Key`]: an image that another loader
/// has decoded (a scene's map and an MTL naming the same file, a reload in `phong serve`) is
/// shared, not decoded again.
static LIVE: Mutex<Vec<(Key, Weak<Texture>)>> = Mutex::new(Vec::new());

/// The texture of `bytes`: one alive in this process, else [`decode_timed`]; what it cost
/// added to `stats`.
fn shared_or_decoded(
    bytes: &[u8],
    srgb: bool,
    start: Instant,
    stats: &mut TextureStats,
) -> Result<Arc<Texture>, String> {
    let key = Key::of(bytes, srgb);
    let live = || LIVE.lock().unwrap_or_else(|e| e.into_inner());
    let found = live().iter().find(|(k, _)| *k == key).and_then(|(_, w)| w.upgrade());
    if let Some(t) = found {
        stats.shared += 1;
        return Ok(t);
    }
    let t = Arc::new(decode_timed(bytes, key, start, stats)?);
    let mut l = live();
    l.retain(|(k, w)| w.strong_count() > 0 && *k != key);
    l.push((key, Arc::downgrade(&t)));
    Ok(t)
}

/// [`decode`], or the texture store's copy where it has one (and the decoded texture kept
/// there), the time added to `stats` (`start`: when decoding began).
fn decode_timed(bytes: &[u8], key: Key, start: Instant, stats: &mut TextureStats) -> Result<Texture, String> {
    let store = texture_store::texture_store().map(|s| (key, s));
    if let Some(t) = store.as_ref().and_then(|(key, s)| texture_store::fetch(s, *key)) {
        stats.images += 1;
        stats.from_store += 1;
        stats.bytes += t.bytes();
        stats.decode += start.elapsed();
        return Ok(t);
    }
    let mut mipmaps = Duration::ZERO;
    let t = decode_with(bytes, key.srgb, &mut mipmaps)?;
    stats.images += 1;
    stats.bytes += t.bytes();
    stats.decode += start.elapsed().saturating_sub(mipmaps);
    stats.mipmaps += mipmaps;
    if let Some((key, s)) = &store {
        let begun = Instant::now();
        let kept = texture_store::keep(s, *key, &t);
        stats.store_writes += begun.elapsed();
        if let Err(why) = kept {
            *STORE_ERROR.lock().unwrap_or_else(|e| e.into_inner()) = Some(why);
            stats.store_failures += 1;
        }
    }
    Ok(t)
}

/// Decodes an image into a texture: 8-bit sources keep 8 bits (read back as `b/255`), 16-bit
/// and float sources 16; with `srgb` the colour channels are decoded to linear (in 16 bits),
/// alpha never is.
pub fn decode(bytes: &[u8], srgb: bool) -> Result<Texture, String> {
    let mut mipmaps = Duration::ZERO;
    decode_with(bytes, srgb, &mut mipmaps)
}

/// [`decode`], the time spent building mipmaps added to `mipmaps`.
fn decode_with(bytes: &[u8], srgb: bool, mipmaps: &mut Duration) -> Result<Texture, String> {
    if bytes.len() as u64 > MAX_IMAGE_FILE_BYTES {
        return Err(format!("larger than {} MiB", MAX_IMAGE_FILE_BYTES >> 20));
    }
    if !srgb && let Some(r) = png8(bytes) {
        let (w, h, texels) = r?;
        let start = Instant::now();
        let t = Texture::from_rgba8_vec(w, h, texels).map_err(|e| e.to_string());
        *mipmaps += start.elapsed();
        return t;
    }
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    limits.max_alloc = Some(MAX_TEXTURE_BYTES);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| e.to_string())?;
    let bits = match img.color() {
        image::ColorType::L8 | image::ColorType::La8 | image::ColorType::Rgb8 | image::ColorType::Rgba8 => 8,
        _ => 16,
    };
    let (w, h) = (img.width(), img.height());
    if bits == 8 && !srgb {
        let rgba = img.into_rgba8().into_raw();
        let start = Instant::now();
        // The decoder's buffer becomes level 0 where its allocation allows (no copy).
        let texels: Vec<[u8; 4]> =
            bytemuck::allocation::try_cast_vec(rgba).unwrap_or_else(|(_, bytes)| bytes.as_chunks::<4>().0.to_vec());
        let t = Texture::from_rgba8_vec(w, h, texels).map_err(|e| e.to_string());
        *mipmaps += start.elapsed();
        return t;
    }
    let rgba = img.into_rgba16();
    let lut: Option<Vec<u16>> = srgb.then(|| {
        (0..=u16::MAX)
            .map(|v| {
                let c = f64::from(v) / 65535.0;
                let l = if c <= 0.04045 {
                    c / 12.92
                } else {
                    ((c + 0.055) / 1.055).powf(2.4)
                };
                (l * 65535.0).round() as u16
            })
            .collect()
    });
    let texels: Vec<[u16; 4]> = rgba
        .pixels()
        .map(|p| match &lut {
            Some(l) => [l[p[0] as usize], l[p[1] as usize], l[p[2] as usize], p[3]],
            None => p.0,
        })
        .collect();
    let start = Instant::now();
    let t = Texture::new(w, h, &texels, if srgb { 16 } else { bits }).map_err(|e| e.to_string());
    *mipmaps += start.elapsed();
    t
}

/// Width, height and texels, top row first.
type Rgba8 = (u32, u32, Vec<[u8; 4]>);

/// An 8-bit, non-interlaced PNG decoded by the `png` crate straight into RGBA texels, a row
/// at a time (`image` decodes the whole image, then converts it into a second buffer: 56 ms
/// of a 4096² RGB image); `None` for any other image, which `image` decodes. Grey is
/// replicated into RGB and a missing alpha is 255, as `image`'s `into_rgba8`.
fn png8(bytes: &[u8]) -> Option<Result<Rgba8, String>> {
    if !bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        return None;
    }
    let mut dec = png::Decoder::new_with_limits(
        std::io::Cursor::new(bytes),
        png::Limits {
            bytes: MAX_TEXTURE_BYTES as usize,
        },
    );
    dec.set_transformations(png::Transformations::EXPAND);
    let mut reader = match dec.read_info() {
        Ok(r) => r,
        Err(e) => return Some(Err(e.to_string())),
    };
    let info = reader.info();
    let (w, h) = (info.width, info.height);
    let (color, depth) = reader.output_color_type();
    if info.interlaced || depth != png::BitDepth::Eight || info.is_animated() {
        return None;
    }
    if w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
        return Some(Err(format!("{w}×{h} is larger than {MAX_TEXTURE_SIDE} texels a side")));
    }
    let mut texels = vec![[0u8, 0, 0, 255]; w as usize * h as usize];
    let mut row = vec![0u8; reader.output_line_size(w)?];
    for out in texels.chunks_exact_mut(w as usize) {
        match reader.read_row(&mut row) {
            Ok(Some(_)) => {}
            Ok(None) => return Some(Err("the image data ends early".into())),
            Err(e) => return Some(Err(e.to_string())),
        }
        match color {
            png::ColorType::Rgba => out.copy_from_slice(row.as_chunks::<4>().0),
            png::ColorType::Rgb => {
                for (o, c) in out.iter_mut().zip(row.as_chunks::<3>().0) {
                    *o = [c[0], c[1], c[2], 255];
                }
            }
            png::ColorType::GrayscaleAlpha => {
                for (o, c) in out.iter_mut().zip(row.as_chunks::<2>().0) {
                    *o = [c[0], c[0], c[0], c[1]];
                }
            }
            png::ColorType::Grayscale => {
                for (o, &g) in out.iter_mut().zip(&row) {
                    *o = [g, g, g, 255];
                }
            }
            png::ColorType::Indexed => return None,
        }
    }
    Some(Ok((w, h, texels)))
}

/// The requests of one material that [`resolve`] loads, and those it does not: a bump map
/// beside a normal map (the one owner of that rule).
fn used(requests: &[MapRequest]) -> (Vec<&MapRequest>, Vec<&MapRequest>) {
    let has_normal_map = requests.iter().any(|r| r.slot == Slot::Normal);
    requests.iter().partition(|r| !(r.slot == Slot::Bump && has_normal_map))
}

/// Decodes ahead, on all cores, the images that the materials' `requests` will load (see
/// [`resolve`]): a model's maps side by side.
pub fn prefetch(materials: &[Vec<MapRequest>], read: &ReadFile, cache: &mut TextureCache) {
    cache.prefetch(materials.iter().flat_map(|m| used(m).0), read);
}

/// A material's maps from its requests, images read by `read` through `cache`; every request
/// that cannot be used is a warning (material `name`), and the material goes without it.
///
/// A scalar map without a channel reads alpha where its image has any (`map_d` as most files
/// mean it), else luminance (MTL's default). An alpha map turns on the alpha test at 0.5.
pub fn resolve(
    requests: &[MapRequest],
    name: &str,
    read: &ReadFile,
    cache: &mut TextureCache,
    warnings: &mut Vec<String>,
) -> Maps {
    let mut maps = Maps::default();
    let (kept, left) = used(requests);
    cache.prefetch(kept.iter().copied(), read);
    for r in left {
        warnings.push(format!(
            "{}: material {name}: bump map {} is not used (the material has a normal map)",
            r.at,
            r.source.name()
        ));
    }
    for r in kept {
        let texture = match cache.load(&r.source, r.srgb && r.slot.is_colour(), read) {
            Ok(t) => t,
            Err(why) => {
                warnings.push(format!(
                    "{}: material {name}: texture {} not used: {why}",
                    r.at,
                    r.source.name()
                ));
                continue;
            }
        };
        let channel = r.channel.unwrap_or(if texture.has_alpha() {
            Channel::A
        } else {
            Channel::Luminance
        });
        let map = TextureMap {
            texture,
            sampler: r.sampler,
            transform: r.transform,
            set: r.set,
        };
        match r.slot {
            Slot::Diffuse => maps.diffuse = Some(map),
            Slot::Ambient => maps.ambient = Some(map),
            Slot::Specular => maps.specular = Some(map),
            Slot::Emission => maps.emission = Some(map),
            Slot::Shininess => maps.shininess = Some((map, channel)),
            Slot::Alpha => {
                maps.alpha = Some((map, channel));
                maps.alpha_cutoff.get_or_insert(0.5);
            }
            Slot::Normal => {
                maps.normal = Some(NormalMap {
                    map,
                    scale: r.scale,
                    green_down: r.green_down,
                })
            }
            Slot::Bump => {
                let channel = r.channel.unwrap_or(Channel::Luminance);
                let made = NormalMap::from_height(&map.texture, channel, r.scale, r.sampler, r.transform)
                    .map_err(|e| e.to_string())
                    .and_then(|n| spend(n.map.texture.bytes()).map(|()| n));
                match made {
                    Ok(n) => maps.normal = Some(n),
                    Err(why) => warnings.push(format!(
                        "{}: material {name}: bump map {} not used: {why}",
                        r.at,
                        r.source.name()
                    )),
                }
            }
            Slot::MetalRough => {
                maps.metal_rough = Some(MetalRough {
                    map,
                    base_factor: phong_core::Color::WHITE,
                    metallic: 1.0,
                    roughness: 1.0,
                })
            }
            Slot::Occlusion => maps.occlusion = Some(Occlusion { map, strength: r.scale }),
        }
    }
    maps
}

/// An MTL texture statement (`map_Kd -s 2 2 -clamp on wood.png`): its slot, the request's
/// transform, wrap and channel from the options, and the file name (the words after the
/// options, spaces kept). Options that are read but not used are returned as warnings;
/// `None` for a statement phong does not use (`disp`, `decal`, `refl`).
pub fn parse_mtl_map(kw: &str, args: &[&str]) -> Result<Option<(MapRequest, Vec<String>)>, String> {
    let slot = match kw {
        "map_Kd" => Slot::Diffuse,
        "map_Ka" => Slot::Ambient,
        "map_Ks" => Slot::Specular,
        "map_Ke" => Slot::Emission,
        "map_Ns" => Slot::Shininess,
        "map_d" => Slot::Alpha,
        "bump" | "map_Bump" | "map_bump" => Slot::Bump,
        "norm" | "map_Kn" => Slot::Normal,
        _ => return Ok(None),
    };
    let mut unused = Vec::new();
    let (mut scale, mut offset) = ([1.0f32; 2], [0.0f32; 2]);
    let mut wrap = Wrap::Repeat;
    let mut channel = None;
    let mut bump = 1.0;
    let mut i = 0;
    let num = |s: &str| s.parse::<f32>().ok().filter(|x| x.is_finite());
    while i < args.len() && args[i].starts_with('-') && num(args[i]).is_none() {
        let opt = args[i];
        i += 1;
        // Options of up to three numbers take those that follow.
        let mut numbers = Vec::new();
        let take = |i: &mut usize, max: usize, numbers: &mut Vec<f32>| {
            while numbers.len() < max && *i < args.len() && num(args[*i]).is_some() {
                numbers.push(num(args[*i]).unwrap_or(0.0));
                *i += 1;
            }
        };
        match opt {
            "-o" | "-s" | "-t" => {
                take(&mut i, 3, &mut numbers);
                if numbers.is_empty() {
                    return Err(format!("{opt} needs numbers"));
                }
                let uv = [numbers[0], *numbers.get(1).unwrap_or(&numbers[0])];
                match opt {
                    "-o" => offset = uv,
                    "-s" => scale = uv,
                    _ => unused.push(format!("{opt} (turbulence)")),
                }
            }
            "-clamp" => {
                let v = args.get(i).copied().unwrap_or("");
                i += 1;
                wrap = match v {
                    "on" => Wrap::Clamp,
                    "off" => Wrap::Repeat,
                    _ => return Err(format!("-clamp takes on or off, got {v:?}")),
                };
            }
            "-imfchan" => {
                let v = args.get(i).copied().unwrap_or("");
                i += 1;
                channel = Some(match v {
                    "r" => Channel::R,
                    "g" => Channel::G,
                    "b" => Channel::B,
                    "l" | "m" | "z" => Channel::Luminance,
                    _ => return Err(format!("-imfchan takes r, g, b, m, l or z, got {v:?}")),
                });
                if !matches!(slot, Slot::Shininess | Slot::Alpha | Slot::Bump) {
                    unused.push(format!("-imfchan {v} (a colour map uses every channel)"));
                }
            }
            "-bm" => {
                take(&mut i, 1, &mut numbers);
                match (slot, numbers.first()) {
                    (Slot::Bump, Some(&k)) => bump = k,
                    (Slot::Bump, None) => return Err("-bm needs a number".into()),
                    _ => unused.push("-bm (only bump maps have a multiplier)".into()),
                }
            }
            "-mm" => {
                take(&mut i, 2, &mut numbers);
                unused.push("-mm".into());
            }
            "-boost" | "-texres" => {
                take(&mut i, 1, &mut numbers);
                unused.push(opt.to_string());
            }
            "-blendu" | "-blendv" | "-cc" | "-type" => {
                i += 1;
                unused.push(opt.to_string());
            }
            _ => unused.push(format!("{opt} (unknown option)")),
        }
    }
    let file = args[i.min(args.len())..].join(" ");
    if file.is_empty() {
        return Err("names no file".into());
    }
    let request = MapRequest {
        slot,
        source: Source::File(file),
        transform: UvTransform::scale_offset(scale.into(), offset.into()),
        sampler: Sampler::trilinear(wrap),
        channel,
        srgb: false,
        at: String::new(),
        scale: bump,
        green_down: false,
        set: 0,
    };
    Ok(Some((request, unused)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtl_options_are_read_and_the_unused_named() {
        let (r, unused) = parse_mtl_map("map_Kd", &["-s", "2", "3", "-o", "0.5", "-clamp", "on", "my wood.png"])
            .unwrap()
            .unwrap();
        assert_eq!(r.slot, Slot::Diffuse);
        assert!(matches!(&r.source, Source::File(f) if f == "my wood.png"));
        assert_eq!(r.transform.apply(glam::Vec2::new(1.0, 1.0)), glam::Vec2::new(2.5, 3.5));
        assert_eq!(r.sampler.wrap_u, Wrap::Clamp);
        assert!(unused.is_empty());
        let (r, unused) = parse_mtl_map("map_Bump", &["-bm", "0.5", "-blendu", "off", "b.png"])
            .unwrap()
            .unwrap();
        assert_eq!(r.slot, Slot::Bump);
        assert_eq!(r.scale, 0.5);
        assert_eq!(unused.len(), 1);
        assert!(parse_mtl_map("bump", &["-bm", "b.png"]).is_err());
        let (r, _) = parse_mtl_map("map_d", &["-imfchan", "r", "a.png"]).unwrap().unwrap();
        assert_eq!(r.channel, Some(Channel::R));
        assert!(parse_mtl_map("map_Kd", &["-clamp", "maybe", "a.png"]).is_err());
        assert!(parse_mtl_map("map_Kd", &["-s", "2"]).is_err());
        assert!(parse_mtl_map("refl", &["a.png"]).unwrap().is_none());
    }

    /// A scene's textures are held to one budget across its loaders: past it, a texture is
    /// refused with a message naming the limit, and a texture already read is not counted
    /// twice; nested budgets share the outer count, and none runs after the outer one ends.
    #[test]
    fn the_scenes_textures_share_one_budget() {
        let mut png = Vec::new();
        image::RgbImage::from_pixel(8, 8, image::Rgb([1, 2, 3]))
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let read = |_: &str| Ok(png.clone());
        let bytes = decode(&png, false).unwrap().bytes();
        {
            let _outer = TextureBudget::with_limit(2 * bytes);
            let _inner = TextureBudget::start();
            let mut cache = TextureCache::default();
            assert!(cache.load(&Source::File("a.png".into()), false, &read).is_ok());
            assert!(
                cache.load(&Source::File("a.png".into()), false, &read).is_ok(),
                "read once"
            );
            let mut other = TextureCache::default();
            assert!(other.load(&Source::File("b.png".into()), false, &read).is_ok());
            let e = other.load(&Source::File("c.png".into()), false, &read).unwrap_err();
            assert!(e.contains("MAX_TEXTURE_BYTES"), "{e}");
        }
        let mut cache = TextureCache::default();
        assert!(
            cache.load(&Source::File("d.png".into()), false, &read).is_ok(),
            "no count left running"
        );
    }

    #[test]
    fn images_decode_at_their_depth() {
        let mut png = Vec::new();
        let img = image::RgbImage::from_fn(3, 2, |x, y| image::Rgb([x as u8 * 100, y as u8 * 200, 7]));
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let t = decode(&png, false).unwrap();
        assert_eq!((t.width(), t.height(), t.bits()), (3, 2, 8));
        // Row 0 is the image's bottom row (y = 1 in the file).
        assert_eq!(t.texel(0, 2, 0), [200.0 / 255.0, 200.0 / 255.0, 7.0 / 255.0, 1.0]);
        let s = decode(&png, true).unwrap();
        let (r, expected) = (s.texel(0, 2, 0)[0], ((200.0f64 / 255.0 + 0.055) / 1.055).powf(2.4));
        assert!((f64::from(r) - expected).abs() < 1e-4, "{r} vs {expected}");
        assert!(decode(b"not an image", false).is_err());
    }

    /// Every kind of PNG, decoded row by row by `png8` (or left to `image`), gives the texels
    /// of `image`'s own decoding and `into_rgba8`.
    #[test]
    fn pngs_of_every_kind_decode_as_image_does() {
        use png::{BitDepth as D, ColorType as C};
        let (w, h) = (5u32, 3u32);
        let kinds: [(C, D, usize, bool); 9] = [
            (C::Grayscale, D::Eight, 1, false),
            (C::Grayscale, D::Two, 1, false),
            (C::GrayscaleAlpha, D::Eight, 2, false),
            (C::Rgb, D::Eight, 3, false),
            (C::Rgb, D::Eight, 3, true),
            (C::Rgba, D::Eight, 4, false),
            (C::Indexed, D::Eight, 1, false),
            (C::Indexed, D::Four, 1, true),
            (C::Rgb, D::Sixteen, 6, false),
        ];
        for (color, depth, bytes_per_pixel, trns) in kinds {
            let bits = depth as usize;
            let row_bytes = (w as usize * bytes_per_pixel * bits.min(8)).div_ceil(8);
            let data: Vec<u8> = (0..row_bytes * h as usize)
                .map(|i| match (color, bits) {
                    // Indices within the palette's 4 entries.
                    (C::Indexed, 8) => (i % 4) as u8,
                    (C::Indexed, _) => ((i % 2) as u8) << 4 | ((i + 1) % 4) as u8,
                    _ => (i as u8).wrapping_mul(53).wrapping_add(9),
                })
                .collect();
            let mut file = Vec::new();
            let mut enc = png::Encoder::new(&mut file, w, h);
            enc.set_color(color);
            enc.set_depth(depth);
            if color == C::Indexed {
                enc.set_palette(vec![10, 20, 30, 40, 50, 60, 70, 80, 90, 250, 240, 230]);
            }
            if trns {
                enc.set_trns(match color {
                    C::Rgb => vec![0, 9, 0, 62, 0, 115],
                    _ => vec![255, 0, 128],
                });
            }
            enc.write_header().unwrap().write_image_data(&data).unwrap();
            let expected = image::load_from_memory(&file).unwrap().into_rgba8();
            let t = decode(&file, false).unwrap();
            let what = format!("{color:?} {depth:?} tRNS {trns}");
            assert_eq!((t.width(), t.height()), (w, h), "{what}");
            assert_eq!(
                png8(&file).is_some(),
                bits <= 8,
                "{what}: row by row where 8 bits or fewer"
            );
            for y in 0..h {
                for x in 0..w {
                    let e = expected.get_pixel(x, h - 1 - y).0;
                    let got = match t.level8(0) {
                        Some((_, _, l)) => l[(y * w + x) as usize],
                        None => t.texel(0, x, y).map(|c| (c * 255.0).round() as u8),
                    };
                    assert_eq!(got, e, "{what} at ({x}, {y})");
                }
            }
        }
        // A cut file: an error, not a panic.
        let mut file = Vec::new();
        let mut enc = png::Encoder::new(&mut file, 64, 64);
        enc.set_color(C::Rgb);
        enc.write_header().unwrap().write_image_data(&[7; 64 * 64 * 3]).unwrap();
        assert!(decode(&file[..file.len() / 2], false).is_err());
    }
}
