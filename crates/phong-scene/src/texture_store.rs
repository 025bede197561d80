//! Decoded textures kept on disk with their mipmaps, so that a large image is decoded once:
//! the next load reads its levels back as they are held in memory (as a renderer's `.tx`
//! files do, made on first use). Off unless [`set_texture_store`] names a folder; `phong`
//! turns it on (docs/models.md, "The texture cache").
//!
//! A file is named by the hash (XXH3-128) of the image's bytes and whether it was decoded
//! from sRGB, and holds its source's length and hash again: a changed image has another
//! name, and a stale, short or foreign file is not used (the image is decoded instead). Files
//! are written whole under a temporary name and renamed; the folder is kept under its size
//! limit by removing the files least recently used.

use phong_core::{SharedBytes, Texture};
use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};
use std::time::SystemTime;

/// Where and what to keep.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TextureStore {
    /// The folder (made where missing).
    pub dir: PathBuf,
    /// Textures smaller than this (bytes, mipmaps included) are not kept: disk is spent only
    /// where decoding costs about a frame or more (benches/HISTORY.md, "The texture cache").
    pub min_bytes: u64,
    /// The folder's files are kept under this many bytes in all.
    pub max_total: u64,
}

impl TextureStore {
    /// The store in `dir` with the default limits: textures from 16 MiB (a 2048² RGBA image
    /// with its mipmaps is 21 MiB), 2 GiB in all.
    pub fn in_dir(dir: PathBuf) -> TextureStore {
        TextureStore {
            dir,
            min_bytes: 16 << 20,
            max_total: 2 << 30,
        }
    }
}

static STORE: RwLock<Option<TextureStore>> = RwLock::new(None);

/// Keeps decoded textures in `store` from now on, for every loader of this process (`None`:
/// none kept, the default).
pub fn set_texture_store(store: Option<TextureStore>) {
    *STORE.write().unwrap_or_else(|e| e.into_inner()) = store;
}

/// The store in use.
pub fn texture_store() -> Option<TextureStore> {
    STORE.read().unwrap_or_else(|e| e.into_inner()).clone()
}

const MAGIC: &[u8; 8] = b"phongtx\x02";
/// Magic, source length, source hash, sRGB, bits, level count, whether any alpha is below 1
/// (saves reading level 0 through once more).
const HEADER: usize = 8 + 8 + 16 + 1 + 1 + 4 + 1;

/// An image's key: its bytes' hash and length, and whether colour was decoded from sRGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Key {
    hash: u128,
    len: u64,
    pub srgb: bool,
}

impl Key {
    pub(crate) fn of(bytes: &[u8], srgb: bool) -> Key {
        Key {
            hash: xxhash_rust::xxh3::xxh3_128(bytes),
            len: bytes.len() as u64,
            srgb,
        }
    }

    fn file(&self, dir: &Path) -> PathBuf {
        dir.join(format!(
            "{:032x}-{}.ptx",
            self.hash,
            if self.srgb { "srgb" } else { "linear" }
        ))
    }

    fn header(&self, bits: u8, levels: u32, translucent: bool) -> [u8; HEADER] {
        let mut h = [0u8; HEADER];
        h[..8].copy_from_slice(MAGIC);
        h[8..16].copy_from_slice(&self.len.to_le_bytes());
        h[16..32].copy_from_slice(&self.hash.to_le_bytes());
        h[32] = u8::from(self.srgb);
        h[33] = bits;
        h[34..38].copy_from_slice(&levels.to_le_bytes());
        h[38] = u8::from(translucent);
        h
    }
}

/// The texture kept for `key` in `store`, if a whole, matching file is there.
pub(crate) fn fetch(store: &TextureStore, key: Key) -> Option<Texture> {
    let mut f = File::open(key.file(&store.dir)).ok()?;
    let mut h = [0u8; HEADER];
    f.read_exact(&mut h).ok()?;
    let count = u32::from_le_bytes(h[34..38].try_into().ok()?);
    if h[..34] != key.header(h[33], count, false)[..34] || count == 0 || count > 32 || h[38] > 1 {
        return None;
    }
    let mut sizes = vec![[0u8; 8]; count as usize];
    f.read_exact(sizes.as_flattened_mut()).ok()?;
    let sizes: Vec<(u32, u32)> = sizes
        .iter()
        .map(|s| {
            let (w, h) = s.split_at(4);
            (
                u32::from_le_bytes(w.try_into().unwrap_or_default()),
                u32::from_le_bytes(h.try_into().unwrap_or_default()),
            )
        })
        .collect();
    // The chain checked before anything is allocated: level 0 within the limits, each level
    // the one before halved (`Texture::from_levels8` checks it again).
    let (w0, h0) = sizes[0];
    let side = phong_core::limits::MAX_TEXTURE_SIDE;
    if w0 == 0 || h0 == 0 || w0 > side || h0 > side {
        return None;
    }
    if sizes
        .windows(2)
        .any(|p| p[1] != ((p[0].0 / 2).max(1), (p[0].1 / 2).max(1)))
    {
        return None;
    }
    // The file holds exactly the header, the sizes and the levels.
    let texel_bytes: u64 = match h[33] {
        8 => 4,
        16 => 8,
        _ => return None,
    };
    let start = (HEADER + 8 * sizes.len()) as u64;
    let data: u64 = sizes
        .iter()
        .map(|&(w, h)| u64::from(w) * u64::from(h) * texel_bytes)
        .sum();
    if f.metadata().ok()?.len() != start + data {
        return None;
    }
    let bytes = read_levels(&f, start, data)?;
    let t = match h[33] {
        8 => Texture::from_shared8(bytes, &sizes, Some(h[38] == 1)),
        _ => Texture::from_shared16(bytes, &sizes, Some(h[38] == 1)),
    }
    .ok()?;
    let _ = f.set_modified(SystemTime::now());
    Some(t)
}

/// `len` bytes from byte `start` of `f`, read into memory of their own that asks for huge
/// pages (fewer page faults: benches/HISTORY.md, "The texture cache read into huge pages"), in
/// pieces spread over the cores.
fn read_levels(f: &File, start: u64, len: u64) -> Option<SharedBytes> {
    let mut map = memmap2::MmapMut::map_anon(usize::try_from(len).ok()?).ok()?;
    // Only a hint: without transparent huge pages the read takes longer, no more.
    #[cfg(target_os = "linux")]
    let _ = map.advise(memmap2::Advice::HugePage);
    const PIECE: usize = 4 << 20;
    let pieces: Vec<(u64, &mut [u8])> = map
        .chunks_mut(PIECE)
        .enumerate()
        .map(|(i, piece)| (start + (i * PIECE) as u64, piece))
        .collect();
    let threads = crate::beside::cores().min(8);
    let read = crate::beside::map(pieces, threads, |(at, buf)| read_at(f, buf, at));
    let ok = read.into_iter().all(|ok| ok);
    let map = map.make_read_only().ok()?;
    ok.then(|| Arc::new(map) as SharedBytes)
}

/// Fills `buf` from byte `at` of `f`.
#[cfg(unix)]
fn read_at(f: &File, buf: &mut [u8], at: u64) -> bool {
    std::os::unix::fs::FileExt::read_exact_at(f, buf, at).is_ok()
}

/// Fills `buf` from byte `at` of `f`.
#[cfg(not(unix))]
fn read_at(mut f: &File, buf: &mut [u8], at: u64) -> bool {
    use std::io::Seek;
    f.seek(std::io::SeekFrom::Start(at)).is_ok() && f.read_exact(buf).is_ok()
}

/// Keeps `t` for `key` in `store` where it is large enough, then trims the folder to its
/// limit. Errors are the caller's to report (nothing is left half-written).
pub(crate) fn keep(store: &TextureStore, key: Key, t: &Texture) -> Result<(), String> {
    if t.bytes() < store.min_bytes || t.bytes() > store.max_total {
        return Ok(());
    }
    let at = |e: std::io::Error| format!("{}: {e}", store.dir.display());
    std::fs::create_dir_all(&store.dir).map_err(at)?;
    let path = key.file(&store.dir);
    let tmp = store.dir.join(format!(
        ".{}.{}.tmp",
        path.file_name().and_then(|n| n.to_str()).unwrap_or("texture"),
        std::process::id()
    ));
    let written = write(&tmp, key, t).and_then(|()| std::fs::rename(&tmp, &path));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(at(e));
    }
    trim(store, &path);
    Ok(())
}

fn write(tmp: &Path, key: Key, t: &Texture) -> std::io::Result<()> {
    let mut out = BufWriter::new(File::create(tmp)?);
    let count = t.level_count();
    out.write_all(&key.header(t.bits(), count as u32, t.has_alpha()))?;
    let size = |(w, h): (u32, u32)| [w.to_le_bytes(), h.to_le_bytes()].concat();
    for i in 0..count {
        let wh = match (t.level8(i), t.level16(i)) {
            (Some((w, h, _)), _) | (_, Some((w, h, _))) => (w, h),
            _ => unreachable!("a level of either storage"),
        };
        out.write_all(&size(wh))?;
    }
    for i in 0..count {
        match (t.level8(i), t.level16(i)) {
            (Some((_, _, x)), _) => out.write_all(bytemuck::cast_slice(x))?,
            (_, Some((_, _, x))) => out.write_all(bytemuck::cast_slice(x))?,
            _ => unreachable!("a level of either storage"),
        }
    }
    out.into_inner().map_err(|e| e.into_error())?;
    Ok(())
}

/// Removes the store's least recently used files until the rest fit its limit (`keep`: the
/// file just written, never removed).
fn trim(store: &TextureStore, keep: &Path) {
    let Ok(entries) = std::fs::read_dir(&store.dir) else {
        return;
    };
    let mut files: Vec<(SystemTime, u64, PathBuf)> = entries
        .flatten()
        .filter_map(|e| {
            let m = e.metadata().ok()?;
            Some((m.modified().ok()?, m.len(), e.path()))
        })
        .collect();
    // A temporary file an hour old was left by a process that stopped while writing it.
    let stale = SystemTime::now() - std::time::Duration::from_secs(3600);
    files.retain(|(when, _, path)| match path.extension().and_then(|x| x.to_str()) {
        Some("ptx") => true,
        Some("tmp") if *when < stale => {
            let _ = std::fs::remove_file(path);
            false
        }
        _ => false,
    });
    let mut total: u64 = files.iter().map(|f| f.1).sum();
    files.sort();
    for (_, len, path) in files {
        if total <= store.max_total {
            break;
        }
        if path != keep && std::fs::remove_file(&path).is_ok() {
            total -= len;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn store(name: &str, min_bytes: u64, max_total: u64) -> TextureStore {
        let dir = std::env::temp_dir().join(format!("phong-store-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        TextureStore {
            dir,
            min_bytes,
            max_total,
        }
    }

    fn texture(w: u32, h: u32, seed: u8) -> Texture {
        let texels: Vec<[u8; 4]> = (0..w * h)
            .map(|i| [(i as u8).wrapping_mul(seed), (i >> 8) as u8, seed, 200])
            .collect();
        Texture::from_rgba8(w, h, &texels).unwrap()
    }

    #[test]
    fn a_kept_texture_reads_back_the_same_and_only_for_its_image() {
        let s = store("same", 0, 1 << 30);
        let t = texture(37, 20, 3);
        let key = Key::of(b"image bytes", false);
        keep(&s, key, &t).unwrap();
        assert_eq!(fetch(&s, key).as_ref(), Some(&t), "every level, bit for bit");
        // Another image, or the same one decoded from sRGB: not this file.
        assert_eq!(fetch(&s, Key::of(b"image bytes!", false)), None);
        assert_eq!(fetch(&s, Key::of(b"image bytes", true)), None);
        // 16 bits too.
        let t16 = Texture::new(3, 5, &[[1, 2, 3, 4]; 15], 16).unwrap();
        let k16 = Key::of(b"sixteen", true);
        keep(&s, k16, &t16).unwrap();
        assert_eq!(fetch(&s, k16), Some(t16));
        // Whether alpha is below 1 is kept, not found again: both ways.
        assert!(fetch(&s, key).unwrap().has_alpha());
        let opaque = Texture::from_rgba8(4, 4, &[[9, 8, 7, 255]; 16]).unwrap();
        let ko = Key::of(b"opaque", false);
        keep(&s, ko, &opaque).unwrap();
        assert!(!fetch(&s, ko).unwrap().has_alpha());
        // It comes from the header (byte 38), not from the texels.
        let mut flipped = std::fs::read(ko.file(&s.dir)).unwrap();
        flipped[38] = 1;
        std::fs::write(ko.file(&s.dir), &flipped).unwrap();
        assert!(fetch(&s, ko).unwrap().has_alpha());
        flipped[38] = 2;
        std::fs::write(ko.file(&s.dir), &flipped).unwrap();
        assert_eq!(fetch(&s, ko), None, "a flag byte that is neither 0 nor 1");
        std::fs::remove_dir_all(&s.dir).unwrap();
    }

    #[test]
    fn a_damaged_file_is_not_used() {
        let s = store("damaged", 0, 1 << 30);
        let t = texture(16, 16, 5);
        let key = Key::of(b"img", false);
        keep(&s, key, &t).unwrap();
        let path = key.file(&s.dir);
        let whole = std::fs::read(&path).unwrap();
        // Cut short, one byte more, a level's size changed, another version's magic.
        std::fs::write(&path, &whole[..whole.len() - 1]).unwrap();
        assert_eq!(fetch(&s, key), None);
        std::fs::write(&path, [&whole[..], &[0]].concat()).unwrap();
        assert_eq!(fetch(&s, key), None);
        let mut bad = whole.clone();
        bad[HEADER] = 15;
        std::fs::write(&path, &bad).unwrap();
        assert_eq!(fetch(&s, key), None);
        let mut bad = whole.clone();
        bad[7] = 1;
        std::fs::write(&path, &bad).unwrap();
        assert_eq!(fetch(&s, key), None);
        std::fs::write(&path, &whole).unwrap();
        assert_eq!(fetch(&s, key), Some(t));
        std::fs::remove_dir_all(&s.dir).unwrap();
    }

    #[test]
    fn small_textures_are_not_kept_and_the_folder_keeps_its_limit() {
        let t = texture(64, 64, 7);
        let size = (HEADER + 7 * 8) as u64 + t.bytes();
        let s = store("small", t.bytes() + 1, 1 << 30);
        keep(&s, Key::of(b"a", false), &t).unwrap();
        assert!(!s.dir.exists(), "below min_bytes: nothing written");
        // Room for two: the third written removes the least recently used.
        let s = store("limit", 0, 2 * size + 10);
        let keys = [b"a", b"b", b"c"].map(|b| Key::of(b, false));
        keep(&s, keys[0], &t).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(20));
        keep(&s, keys[1], &t).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(20));
        // Reading `a` makes `b` the least recently used.
        assert!(fetch(&s, keys[0]).is_some());
        std::thread::sleep(std::time::Duration::from_millis(20));
        keep(&s, keys[2], &t).unwrap();
        let there = keys.map(|k| k.file(&s.dir).exists());
        assert_eq!(there, [true, false, true]);
        // Temporary files left by a stopped writer: removed once an hour old, not before.
        let (old, new) = (s.dir.join(".x.ptx.1.tmp"), s.dir.join(".y.ptx.2.tmp"));
        for f in [&old, &new] {
            std::fs::write(f, b"partial").unwrap();
        }
        let two_hours = SystemTime::now() - std::time::Duration::from_secs(7200);
        File::options()
            .write(true)
            .open(&old)
            .unwrap()
            .set_modified(two_hours)
            .unwrap();
        keep(&s, keys[1], &t).unwrap();
        assert!(!old.exists() && new.exists());
        std::fs::remove_dir_all(&s.dir).unwrap();
    }
}
