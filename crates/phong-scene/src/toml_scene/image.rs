//! `[image]`: size, background, antialias, encoding.

use super::choices::ENCODINGS;
use super::ctx::Ctx;
use super::raw::RawImage;
use crate::Error;
use phong_core::limits::MAX_IMAGE_DIMENSION;
use phong_core::{ImageSettings, Samples};

pub(super) fn image_settings(ctx: &Ctx, r: RawImage) -> Result<ImageSettings, Error> {
    let mut s = ImageSettings::default();
    let max = i64::from(MAX_IMAGE_DIMENSION);
    if let Some(w) = &r.width {
        s.width = ctx.int(w, "width", 1, max)? as u32;
    }
    if let Some(h) = &r.height {
        s.height = ctx.int(h, "height", 1, max)? as u32;
    }
    if let Some(b) = &r.background {
        let v = b.get_ref();
        if !(v.len() == 3 || v.len() == 4) || v.iter().any(|x| !x.is_finite() || !(0.0..=1.0).contains(x)) {
            return ctx.err(
                &b.span(),
                "background",
                "expected [r, g, b] or [r, g, b, a] with values in [0, 1]",
            );
        }
        s.background = [v[0], v[1], v[2], v.get(3).copied().unwrap_or(1.0)];
    }
    if let Some(a) = &r.antialias {
        let v = *a.get_ref();
        let samples = u32::try_from(v).ok().and_then(|n| Samples::from_count(n).ok());
        let Some(samples) = samples else {
            return ctx.err(
                &a.span(),
                "antialias",
                format!("must be 1, 4 or 16 samples per pixel, got {v}"),
            );
        };
        s.samples = samples;
    }
    if let Some(e) = &r.encoding {
        s.encoding = ctx.choice(e, "encoding", ENCODINGS)?;
    }
    // The core's check of the whole (pixels × samples), at the key that made it too large.
    if let Err(e) = s.check() {
        let (span, key) = match (&r.antialias, &r.width, &r.height) {
            (Some(a), ..) => (a.span(), "antialias"),
            (None, Some(w), _) => (w.span(), "width"),
            (None, None, Some(h)) => (h.span(), "height"),
            (None, None, None) => (0..0, "image"),
        };
        return ctx.err(&span, key, e.to_string());
    }
    Ok(s)
}
