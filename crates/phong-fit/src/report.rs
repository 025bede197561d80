//! The fit's pictures: target | fit | difference side by side, and the error against the
//! exponent.

use crate::image::Target;
use phong_core::{Color, Encoding, Image};

/// Target, fit and `4·|difference|` side by side, in `encoding`'s linear values.
pub fn comparison(target: &Target, fit: &Image, used: &[bool]) -> Image {
    let (w, h) = (target.width, target.height);
    let mut out = Image::new(w * 3, h, [0.0, 0.0, 0.0, 1.0]).expect("a valid size");
    let px = out.pixels_mut();
    for y in 0..h as usize {
        for x in 0..w as usize {
            let p = y * w as usize + x;
            let t = target.rgb[p];
            let f = fit.pixels()[p];
            let row = y * 3 * w as usize;
            px[row + x] = [t[0], t[1], t[2], 1.0];
            px[row + w as usize + x] = [f[0], f[1], f[2], 1.0];
            let d = if used[p] {
                [0, 1, 2].map(|c| ((f[c] - t[c]).abs() * 4.0).min(1.0))
            } else {
                [0.0, 0.0, 0.1]
            };
            px[row + 2 * w as usize + x] = [d[0], d[1], d[2], 1.0];
        }
    }
    out
}

/// A plot of `curve` (`(s, error)`, `s` on a log axis), the chosen `s` marked.
pub fn error_plot(curve: &[(f32, f64)], chosen: f32, title: &str) -> Image {
    let (w, h) = (720u32, 400u32);
    let mut img = Image::new(w, h, [0.05, 0.05, 0.07, 1.0]).expect("a valid size");
    let (m, top) = (60.0, 40.0);
    let (x0, x1) = (m, w as f32 - 20.0);
    let (y0, y1) = (h as f32 - 40.0, top);
    let pts: Vec<(f32, f64)> = curve
        .iter()
        .filter(|(s, e)| *s > 0.0 && e.is_finite())
        .copied()
        .collect();
    let (smin, smax) = pts.iter().fold((f32::MAX, f32::MIN), |(a, b), (s, _)| {
        (a.min(s.log10()), b.max(s.log10()))
    });
    let emax = pts.iter().fold(0.0f64, |a, (_, e)| a.max(*e)).max(1e-9);
    let sx = |s: f32| x0 + (s.log10() - smin) / (smax - smin).max(1e-6) * (x1 - x0);
    let sy = |e: f64| y0 - (e / emax) as f32 * (y0 - y1);
    let grey = Color::splat(0.35);
    line(&mut img, (x0, y0), (x1, y0), grey);
    line(&mut img, (x0, y0), (x0, y1), grey);
    for win in pts.windows(2) {
        line(
            &mut img,
            (sx(win[0].0), sy(win[0].1)),
            (sx(win[1].0), sy(win[1].1)),
            Color::new(0.94, 0.7, 0.16),
        );
    }
    if chosen > 0.0 {
        line(
            &mut img,
            (sx(chosen), y0),
            (sx(chosen), y1),
            Color::new(0.3, 0.75, 0.95),
        );
    }
    let white = Color::splat(0.9);
    phong_core::text::draw_text(&mut img, 10, 10, title, white, 2);
    phong_core::text::draw_text(
        &mut img,
        x0 as i64,
        (y0 + 10.0) as i64,
        &format!("s = {:.3}", 10f32.powf(smin)),
        white,
        1,
    );
    phong_core::text::draw_text(
        &mut img,
        (x1 - 90.0) as i64,
        (y0 + 10.0) as i64,
        &format!("s = {:.0}", 10f32.powf(smax)),
        white,
        1,
    );
    phong_core::text::draw_text(&mut img, 4, (y1 - 4.0) as i64, &format!("{emax:.4}"), white, 1);
    phong_core::text::draw_text(
        &mut img,
        (sx(chosen) + 4.0) as i64,
        (y1 + 4.0) as i64,
        &format!("fit s = {chosen:.2}"),
        white,
        1,
    );
    img
}

fn line(img: &mut Image, a: (f32, f32), b: (f32, f32), c: Color) {
    let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) as usize).max(1);
    let (w, h) = (img.width() as i64, img.height() as i64);
    for i in 0..=steps {
        let t = i as f32 / steps as f32;
        let (x, y) = ((a.0 + (b.0 - a.0) * t) as i64, (a.1 + (b.1 - a.1) * t) as i64);
        if (0..w).contains(&x) && (0..h).contains(&y) {
            img.pixels_mut()[(y * w + x) as usize] = [c.r, c.g, c.b, 1.0];
        }
    }
}

/// Polar plots of a BRDF fit's lobes in the plane of incidence, light at 0°, 30° and 60°:
/// the radius is `f·cos θ_l` towards each outgoing direction; target orange, fit blue.
pub fn lobe_plot(target: impl Fn([f64; 3], [f64; 3]) -> Option<f64>, fit: impl Fn([f64; 3], [f64; 3]) -> f64) -> Image {
    let (w, h) = (960u32, 340u32);
    let mut img = Image::new(w, h, [0.05, 0.05, 0.07, 1.0]).expect("a valid size");
    let angles = [0.0f64, 30.0, 60.0];
    let orange = Color::new(0.94, 0.7, 0.16);
    let blue = Color::new(0.3, 0.75, 0.95);
    for (k, deg) in angles.iter().enumerate() {
        let ti = deg.to_radians();
        let l = [-ti.sin(), 0.0, ti.cos()];
        let lobe = |f: &dyn Fn([f64; 3]) -> Option<f64>| -> Vec<(f64, f64)> {
            (-89..=89)
                .filter_map(|a| {
                    let t = f64::from(a).to_radians();
                    f([t.sin(), 0.0, t.cos()]).map(|r| (t, r))
                })
                .collect()
        };
        let tc = lobe(&|v| target(l, v));
        let fc = lobe(&|v| Some(fit(l, v)));
        let rmax = tc.iter().chain(&fc).fold(1e-9f64, |a, (_, r)| a.max(*r));
        let (cx, cy, radius) = (k as f32 * 320.0 + 160.0, h as f32 - 30.0, 140.0);
        let at = |t: f64, r: f64| {
            (
                cx + (t.sin() * r / rmax) as f32 * radius,
                cy - (t.cos() * r / rmax) as f32 * radius,
            )
        };
        // The surface, the normal and the incident direction.
        let grey = Color::splat(0.35);
        line(&mut img, (cx - radius, cy), (cx + radius, cy), grey);
        line(&mut img, (cx, cy), (cx, cy - radius), grey);
        line(&mut img, (cx, cy), at(-ti, rmax * 0.9), Color::splat(0.8));
        for (c, col) in [(&tc, orange), (&fc, blue)] {
            for win in c.windows(2) {
                line(&mut img, at(win[0].0, win[0].1), at(win[1].0, win[1].1), col);
            }
        }
        phong_core::text::draw_text(
            &mut img,
            (cx - 150.0) as i64,
            12,
            &format!("light at {deg:.0} deg"),
            Color::splat(0.9),
            1,
        );
    }
    phong_core::text::draw_text(&mut img, 12, h as i64 - 16, "target", orange, 1);
    phong_core::text::draw_text(&mut img, 72, h as i64 - 16, "fit", blue, 1);
    img
}

/// Writes `img` as a PNG (linear values as they are).
pub fn write(path: &std::path::Path, img: &Image) -> Result<(), crate::FitError> {
    phong_scene::write_png(path, img, Encoding::Linear).map_err(|e| crate::FitError::Input(e.to_string()))
}
