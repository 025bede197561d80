//! Images: linear RGBA in `f32`, and their 8-bit encodings.

use crate::{Color, Error};

/// How linear colours become 8-bit values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Encoding {
    /// `round(255·clamp(c, 0, 1))`: colours written as computed, as OpenGL does by default.
    #[default]
    Linear,
    /// The sRGB transfer curve (IEC 61966-2-1): `12.92c` for `c <= 0.0031308`,
    /// else `1.055c^(1/2.4) − 0.055`.
    Srgb,
}

impl Encoding {
    /// The 8-bit value of the linear component `c`.
    #[inline]
    pub fn encode(self, c: f32) -> u8 {
        let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
        let e = match self {
            Encoding::Linear => c,
            Encoding::Srgb => {
                if c <= 0.003_130_8 {
                    12.92 * c
                } else {
                    1.055 * c.powf(1.0 / 2.4) - 0.055
                }
            }
        };
        (e * 255.0 + 0.5) as u8
    }
}

/// A `width × height` image of linear, straight-alpha RGBA `f32` pixels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 4]>,
}

impl Image {
    /// An image filled with `fill`; sizes from 1 to [`MAX_IMAGE_DIMENSION`](crate::limits::MAX_IMAGE_DIMENSION).
    pub fn new(width: u32, height: u32, fill: [f32; 4]) -> Result<Self, Error> {
        check_size(width, height)?;
        Ok(Image {
            width,
            height,
            pixels: vec![fill; width as usize * height as usize],
        })
    }

    /// An image from its pixels, row-major from the top.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<[f32; 4]>) -> Result<Self, Error> {
        check_size(width, height)?;
        if pixels.len() != width as usize * height as usize {
            return Err(Error::OutOfRange {
                what: "pixel count",
                range: "width × height",
                value: pixels.len() as f32,
            });
        }
        Ok(Image { width, height, pixels })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Pixels, row-major from the top.
    pub fn pixels(&self) -> &[[f32; 4]] {
        &self.pixels
    }
    /// Mutable pixels.
    pub fn pixels_mut(&mut self) -> &mut [[f32; 4]] {
        &mut self.pixels
    }
    /// Pixel `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }
    /// The RGB of pixel `(x, y)`.
    pub fn color(&self, x: u32, y: u32) -> Color {
        let [r, g, b, _] = self.get(x, y);
        Color::new(r, g, b)
    }
    /// True when some pixel is not fully opaque.
    pub fn has_transparency(&self) -> bool {
        self.pixels.iter().any(|p| p[3] < 1.0)
    }

    /// 8-bit RGB (or RGBA when `alpha`), row-major.
    pub fn to_bytes(&self, encoding: Encoding, alpha: bool) -> Vec<u8> {
        let ch = if alpha { 4 } else { 3 };
        let mut out = Vec::with_capacity(self.pixels.len() * ch);
        for p in &self.pixels {
            out.extend(p[..3].iter().map(|&c| encoding.encode(c)));
            if alpha {
                out.push(Encoding::Linear.encode(p[3]));
            }
        }
        out
    }
}

/// A `width × height` image of 8-bit straight-alpha RGBA pixels, row 0 at the top: an
/// [`Image`] as [`Image::to_bytes`] encodes it (colour by `encoding`, alpha linearly), made
/// directly by a renderer that writes its tiles in 8 bits.
#[derive(Clone, Debug, PartialEq)]
pub struct Image8 {
    width: u32,
    height: u32,
    encoding: Encoding,
    pixels: Vec<[u8; 4]>,
}

impl Image8 {
    /// A zeroed image; sizes as for [`Image::new`].
    pub fn new(width: u32, height: u32, encoding: Encoding) -> Result<Self, Error> {
        check_size(width, height)?;
        Ok(Image8 {
            width,
            height,
            encoding,
            pixels: vec![[0; 4]; width as usize * height as usize],
        })
    }

    /// Whether 8-bit pixels tell transparency as [`Image::has_transparency`] does (an alpha
    /// below 1) for every image whose background alpha is `alpha`: its pixels' alphas are
    /// `(k + (n − k)·alpha) / n` for `k` of `n ≤ 16` samples covered, which round to 255 while
    /// below 1 only when `alpha` lies in `(1 − 8/255, 1)`.
    pub fn exact_for_background(alpha: f32) -> bool {
        alpha == 1.0 || alpha <= 1.0 - 8.0 / 255.0
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// The encoding of the colour channels.
    pub fn encoding(&self) -> Encoding {
        self.encoding
    }
    /// Pixels, row-major from the top.
    pub fn pixels(&self) -> &[[u8; 4]] {
        &self.pixels
    }
    /// Mutable pixels.
    pub fn pixels_mut(&mut self) -> &mut [[u8; 4]] {
        &mut self.pixels
    }
    /// Whether any pixel is not opaque.
    pub fn has_transparency(&self) -> bool {
        // Blocks' least alpha (a fold the compiler vectorises), not a test per pixel.
        self.pixels
            .chunks(1024)
            .any(|b| b.iter().fold(255u8, |m, p| m.min(p[3])) < 255)
    }
    /// RGB (or RGBA when `alpha`) bytes, row-major.
    pub fn to_bytes(&self, alpha: bool) -> Vec<u8> {
        if alpha {
            return bytemuck::cast_slice(&self.pixels).to_vec();
        }
        let mut out = vec![0u8; self.pixels.len() * 3];
        for (o, p) in out.chunks_exact_mut(3).zip(&self.pixels) {
            o.copy_from_slice(&p[..3]);
        }
        out
    }
}

/// What labels are drawn on: an [`Image`], or an [`Image8`] (whose pixels are the encoded
/// colour, opaque).
pub trait Canvas {
    /// Width and height in pixels.
    fn size(&self) -> (u32, u32);
    /// Sets pixel `(x, y)` to the opaque colour `c`.
    fn put(&mut self, x: u32, y: u32, c: crate::Color);
}

impl Canvas for Image {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
    fn put(&mut self, x: u32, y: u32, c: crate::Color) {
        self.pixels[y as usize * self.width as usize + x as usize] = [c.r, c.g, c.b, 1.0];
    }
}

impl Canvas for Image8 {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
    fn put(&mut self, x: u32, y: u32, c: crate::Color) {
        let e = self.encoding;
        self.pixels[y as usize * self.width as usize + x as usize] = [e.encode(c.r), e.encode(c.g), e.encode(c.b), 255];
    }
}

fn check_size(width: u32, height: u32) -> Result<(), Error> {
    let max = crate::limits::MAX_IMAGE_DIMENSION;
    for (what, v) in [("image width", width), ("image height", height)] {
        if v == 0 || v > max {
            return Err(Error::OutOfRange {
                what,
                range: "from 1 to 16384 pixels",
                value: v as f32,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodings() {
        assert_eq!(Encoding::Linear.encode(0.5), 128);
        assert_eq!(Encoding::Linear.encode(1.5), 255);
        assert_eq!(Encoding::Linear.encode(f32::NAN), 0);
        // sRGB(0.5) = 1.055·0.5^(1/2.4) − 0.055 = 0.735357 → 187.5 → 188
        assert_eq!(Encoding::Srgb.encode(0.5), 188);
        assert_eq!(Encoding::Srgb.encode(0.002), 7); // 12.92·0.002·255 = 6.59
    }

    #[test]
    fn size_limits() {
        assert!(Image::new(0, 10, [0.0; 4]).is_err());
        assert!(Image::new(1_000_000, 10, [0.0; 4]).is_err());
        assert!(Image::new(16384, 1, [0.0; 4]).is_ok());
    }

    /// An 8-bit image's transparency is found wherever its one non-opaque pixel is (first,
    /// last, either side of the blocks' bounds), and its bytes are its pixels' channels in
    /// order.
    #[test]
    fn image8_transparency_and_bytes() {
        let (w, h) = (67, 41);
        let mut image = Image8::new(w, h, Encoding::Linear).unwrap();
        for (i, p) in image.pixels_mut().iter_mut().enumerate() {
            *p = [i as u8, (i >> 8) as u8, 7, 255];
        }
        assert!(!image.has_transparency());
        let n = (w * h) as usize;
        for at in [0, 1023, 1024, 1025, 2047, 2048, n - 1] {
            let mut one = image.clone();
            one.pixels_mut()[at][3] = 254;
            assert!(one.has_transparency(), "pixel {at}");
        }
        let rgb = image.to_bytes(false);
        let rgba = image.to_bytes(true);
        assert_eq!((rgb.len(), rgba.len()), (3 * n, 4 * n));
        for i in [0, 1, 1000, n - 1] {
            let p = [i as u8, (i >> 8) as u8, 7];
            assert_eq!(rgb[3 * i..3 * i + 3], p);
            assert_eq!(rgba[4 * i..4 * i + 4], [p[0], p[1], p[2], 255]);
        }
    }
}
