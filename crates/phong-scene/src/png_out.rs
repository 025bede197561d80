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
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(err(e));
    }
    Ok(())
}

/// The PNG file of `bytes`: fast compression (encoding time dominated the write).
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
