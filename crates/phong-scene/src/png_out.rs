//! PNG output, written atomically: to a temporary file beside the target,
//! then renamed over it, so a failed write never leaves a partial image.

use crate::Error;
use phong_core::{Encoding, Image, Image8};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `image` as an 8-bit PNG: RGB, or RGBA when some pixel is not
/// opaque; colours encoded with `encoding` (sRGB adds the PNG `sRGB` chunk).
pub fn write_png(path: &Path, image: &Image, encoding: Encoding) -> Result<(), Error> {
    let alpha = image.has_transparency();
    let bytes = image.to_bytes(encoding, alpha);
    write_bytes(path, (image.width(), image.height()), &bytes, alpha, encoding)
}

/// [`write_png`] for an image already in 8 bits (the same file as for the `f32` image it
/// encodes).
pub fn write_png8(path: &Path, image: &Image8) -> Result<(), Error> {
    let alpha = image.has_transparency();
    let bytes = image.to_bytes(alpha);
    write_bytes(path, (image.width(), image.height()), &bytes, alpha, image.encoding())
}

/// The PNG file that [`write_png8`] writes, in memory (the server sends these bytes).
pub fn encode_png8(image: &Image8) -> Result<Vec<u8>, std::io::Error> {
    let alpha = image.has_transparency();
    let bytes = image.to_bytes(alpha);
    encode((image.width(), image.height()), &bytes, alpha, image.encoding())
}

/// The PNG file that [`write_png`] writes, in memory.
pub fn encode_png(image: &Image, encoding: Encoding) -> Result<Vec<u8>, std::io::Error> {
    let alpha = image.has_transparency();
    let bytes = image.to_bytes(encoding, alpha);
    encode((image.width(), image.height()), &bytes, alpha, encoding)
}

/// RGBA bytes (`width`·`height`·4, rows top first) as the PNG file phong writes: RGB where
/// every alpha is 255, else RGBA, with no colour-space chunk.
pub fn encode_rgba8(width: u32, height: u32, rgba: &[u8]) -> Result<Vec<u8>, std::io::Error> {
    if rgba.len() as u64 != u64::from(width) * u64::from(height) * 4 {
        return Err(std::io::Error::other(format!(
            "{} bytes are not a {width}x{height} RGBA image",
            rgba.len()
        )));
    }
    if rgba.chunks_exact(4).all(|p| p[3] == 255) {
        let rgb: Vec<u8> = rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        encode((width, height), &rgb, false, Encoding::Linear)
    } else {
        encode((width, height), rgba, true, Encoding::Linear)
    }
}

/// Whether `path` holds a whole PNG file: its signature, and its IEND chunk at the end (what a
/// write cut short lacks).
pub fn is_complete_png(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];
    const IEND: [u8; 12] = [0, 0, 0, 0, b'I', b'E', b'N', b'D', 0xae, 0x42, 0x60, 0x82];
    let Ok(mut f) = std::fs::File::open(path) else {
        return false;
    };
    let (mut head, mut tail) = ([0u8; 8], [0u8; 12]);
    f.read_exact(&mut head).is_ok()
        && head == SIGNATURE
        && f.seek(SeekFrom::End(-12)).is_ok()
        && f.read_exact(&mut tail).is_ok()
        && tail == IEND
}

/// `bytes` (RGB, or RGBA with `alpha`) as a PNG at `path`, atomically.
fn write_bytes(path: &Path, size: (u32, u32), bytes: &[u8], alpha: bool, encoding: Encoding) -> Result<(), Error> {
    let err = |source: std::io::Error| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    let buf = encode(size, bytes, alpha, encoding).map_err(err)?;
    write_file(path, &buf)
}

/// Writes `bytes` to `path` atomically: to a temporary file beside it, then renamed over it.
/// Not flushed to the disk (no `fsync`): a reader never sees a half-written file, and a file
/// that a machine's crash leaves short is found incomplete and redone by `phong batch`; an
/// `fsync` a file was 3–10% of a batch of thumbnails on a local disk (301 of them: 29–89 ms of
/// 0.74–1.0 s, 2026-12-05); on a network filesystem each is a round trip to the server (not
/// measured here).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let err = |source: std::io::Error| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    let buf = bytes;
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(buf)?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(err(e));
    }
    Ok(())
}

/// The PNG file of `bytes`: fast compression (encoding time dominated the write), every row
/// filtered by Paeth (BENCHMARKS.md, C13).
fn encode(
    (width, height): (u32, u32),
    bytes: &[u8],
    alpha: bool,
    encoding: Encoding,
) -> Result<Vec<u8>, std::io::Error> {
    let err = std::io::Error::other;
    let mut buf = Vec::with_capacity(bytes.len() / 2);
    {
        let mut enc = png::Encoder::new(&mut buf, width, height);
        enc.set_color(if alpha {
            png::ColorType::Rgba
        } else {
            png::ColorType::Rgb
        });
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        enc.set_filter(png::Filter::Paeth);
        if encoding == Encoding::Srgb {
            enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        }
        let mut w = enc.write_header().map_err(err)?;
        w.write_image_data(bytes).map_err(err)?;
        w.finish().map_err(err)?;
    }
    Ok(buf)
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}
