//! The fits against known answers: targets rendered from known materials (8-bit, with noise),
//! BRDFs written as MERL files from known parameters, GGX against `s ≈ 2/α² − 2`.

use glam::Vec3;
use phong_core::{
    Attenuation, Camera, Color, Encoding, ImageSettings, Interpolation, Light, LightColor, Lighting, Material, Object,
    Output, Projection, Scene, ShadingOptions, ShadingSettings, SpecularModel, Viewer, primitives,
};
use phong_fit::brdf::{Brdf, Merl, fit_brdf};
use phong_fit::image::{Free, Target, fit_image};
use phong_raster::RenderOptions;
use std::f64::consts::PI;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (u, v) = (self.next().max(1e-12), self.next());
        (-2.0 * u.ln()).sqrt() * (2.0 * PI * v).cos()
    }
}

fn scene(lights: Vec<Light>, options: ShadingOptions, material: Material, interpolation: Interpolation) -> Scene {
    let camera = Camera::new(
        Vec3::new(0.0, 0.3, 3.5),
        Vec3::ZERO,
        Vec3::Y,
        Projection::Perspective { fov_y_deg: 40.0 },
        0.1,
        20.0,
    )
    .expect("camera");
    let shading = ShadingSettings {
        options,
        interpolation,
        viewer: Viewer::Local,
        output: Output::Color,
    };
    Scene {
        image: ImageSettings {
            width: 160,
            height: 160,
            ..ImageSettings::default()
        },
        camera,
        lighting: Lighting::new(Color::splat(0.2), lights).expect("lights"),
        objects: vec![Object {
            name: "sphere".into(),
            mesh: primitives::sphere(96),
            material,
            shading,
            maps: Default::default(),
        }],
        labels: Vec::new(),
    }
}

/// The scene's image as an 8-bit target with noise σ = `noise`/255.
fn target(scene: &Scene, rng: &mut Rng, noise: f64) -> Target {
    let img = phong_raster::render(scene, &RenderOptions::default()).expect("render");
    let (mut rgb, mut clipped) = (Vec::new(), Vec::new());
    for p in img.pixels() {
        let q = [0, 1, 2].map(|c| {
            (f64::from(p[c]) * 255.0 + rng.gauss() * noise)
                .round()
                .clamp(0.0, 255.0)
        });
        clipped.push(q.map(|v| v == 0.0 || v == 255.0));
        rgb.push(q.map(|v| (v / 255.0) as f32));
    }
    Target {
        width: img.width(),
        height: img.height(),
        rgb,
        clipped,
        censor: (0.5 / 255.0, 254.5 / 255.0),
    }
}

fn lights(setup: usize) -> Vec<Light> {
    let white = |c: f32| LightColor::uniform(Color::splat(c)).expect("colour");
    match setup {
        0 => vec![Light::point(Vec3::new(2.0, 2.0, 3.0), white(1.0), Attenuation::NONE).expect("light")],
        1 => vec![
            Light::directional(Vec3::new(-1.0, -0.6, -1.0), white(0.8)).expect("light"),
            Light::point(
                Vec3::new(-2.0, 1.0, 2.5),
                white(0.5),
                Attenuation::new(1.0, 0.1, 0.02).expect("att"),
            )
            .expect("light"),
        ],
        _ => vec![
            Light::spot(
                Vec3::new(0.5, 3.0, 2.0),
                Vec3::new(-0.15, -1.0, -0.7),
                40.0,
                2.0,
                white(1.0),
                Attenuation::NONE,
            )
            .expect("light"),
            Light::directional(Vec3::new(0.5, -0.2, -1.0), white(0.3)).expect("light"),
        ],
    }
}

#[test]
fn recovers_known_materials_from_noisy_8_bit_targets() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let models = [
        (
            "phong",
            ShadingOptions {
                specular: SpecularModel::Phong,
                ..ShadingOptions::default()
            },
        ),
        ("blinn-phong", ShadingOptions::default()),
        ("opengl", ShadingOptions::opengl(false)),
        (
            "lyon",
            ShadingOptions {
                specular: SpecularModel::Lyon {
                    squarings: 4,
                    lambda: phong_core::LyonLambda::Dot,
                },
                ..ShadingOptions::default()
            },
        ),
    ];
    let (mut worst_colour, mut worst_s) = (0.0f64, 0.0f64);
    for (mi, (name, options)) in models.iter().enumerate() {
        for setup in 0..3 {
            let c = |rng: &mut Rng, lo: f64, hi: f64| {
                Color::new(
                    (lo + rng.next() * (hi - lo)) as f32,
                    (lo + rng.next() * (hi - lo)) as f32,
                    (lo + rng.next() * (hi - lo)) as f32,
                )
            };
            let truth = Material::new(
                c(&mut rng, 0.05, 0.3),
                c(&mut rng, 0.2, 0.6),
                c(&mut rng, 0.2, 0.5),
                Color::BLACK,
                (10.0 * (100.0f64).powf(rng.next())) as f32,
            )
            .expect("material");
            let interp = if (mi + setup) % 3 == 2 {
                Interpolation::Gouraud
            } else {
                Interpolation::Phong
            };
            let sc = scene(lights(setup), *options, truth, interp);
            let t = target(&sc, &mut rng, 1.0);
            let start = scene(lights(setup), *options, Material::default(), interp);
            let fit = fit_image(&start, 0, &t, Free::default_set(), None, RenderOptions::default()).expect("a fit");
            let m = fit.material;
            for (what, a, b) in [
                ("ambient", m.ambient(), truth.ambient()),
                ("diffuse", m.diffuse(), truth.diffuse()),
                ("specular", m.specular(), truth.specular()),
            ] {
                let e = [a.r - b.r, a.g - b.g, a.b - b.b]
                    .iter()
                    .fold(0.0f64, |x, d| x.max(f64::from(d.abs())));
                worst_colour = worst_colour.max(e);
                // Measured: at most 0.0028 over these 12 fits; asserted at twice that.
                assert!(e < 0.006, "{name} setup {setup} {interp:?}: {what} {a:?} vs {b:?}");
            }
            let es = (f64::from(m.shininess()) / f64::from(truth.shininess()) - 1.0).abs();
            worst_s = worst_s.max(es);
            // Measured: at most 0.9% (the issue asks 5%); asserted at 2%.
            assert!(
                es < 0.02,
                "{name} setup {setup}: shininess {} vs {}",
                m.shininess(),
                truth.shininess()
            );
            assert!(fit.undetermined.is_empty(), "{:?}", fit.undetermined);
            assert!(fit.psnr > 40.0, "psnr {}", fit.psnr);
        }
    }
    eprintln!("worst colour error {worst_colour:.4}, worst relative exponent error {worst_s:.4}");
}

#[test]
fn says_when_no_highlight_determines_the_specular_term() {
    let mut rng = Rng(5);
    let lambert = Material::new(
        Color::splat(0.1),
        Color::new(0.5, 0.4, 0.3),
        Color::BLACK,
        Color::BLACK,
        10.0,
    )
    .expect("m");
    let sc = scene(lights(0), ShadingOptions::default(), lambert, Interpolation::Phong);
    let t = target(&sc, &mut rng, 1.0);
    let fit = fit_image(&sc, 0, &t, Free::default_set(), None, RenderOptions::default()).expect("fit");
    assert!(
        fit.undetermined.iter().any(|u| u.starts_with("specular and shininess")),
        "{:?}",
        fit.undetermined
    );
    assert!((fit.material.diffuse().r - 0.5).abs() < 0.02);
    // Emission and ambient cannot be told apart under a uniform ambient light.
    let mut free = Free::default_set();
    free.emission = true;
    let fit = fit_image(&sc, 0, &t, free, None, RenderOptions::default()).expect("fit");
    assert!(
        fit.undetermined.iter().any(|u| u.starts_with("emission")),
        "{:?}",
        fit.undetermined
    );
}

#[test]
fn bad_targets_are_refused() {
    let mut rng = Rng(11);
    let sc = scene(
        lights(0),
        ShadingOptions::default(),
        Material::default(),
        Interpolation::Phong,
    );
    let t = target(&sc, &mut rng, 0.0);
    let err = |r: Result<phong_fit::image::ImageFit, phong_fit::FitError>| match r {
        Err(phong_fit::FitError::Input(m)) => m,
        Err(e) => panic!("not an input error: {e}"),
        Ok(_) => panic!("accepted"),
    };
    let mut small = scene(
        lights(0),
        ShadingOptions::default(),
        Material::default(),
        Interpolation::Phong,
    );
    small.image.width = 100;
    let m = err(fit_image(
        &small,
        0,
        &t,
        Free::default_set(),
        None,
        RenderOptions::default(),
    ));
    assert!(m.contains("160x160") && m.contains("100x160"), "{m}");
    // The camera looks away: no pixel of the sphere.
    let mut away = sc.clone();
    away.camera = Camera::new(
        Vec3::new(0.0, 0.0, 3.5),
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::Y,
        Projection::Perspective { fov_y_deg: 40.0 },
        0.1,
        20.0,
    )
    .expect("camera");
    let m = err(fit_image(
        &away,
        0,
        &t,
        Free::default_set(),
        None,
        RenderOptions::default(),
    ));
    assert!(m.contains("no pixel shows object 0"), "{m}");
    // Every pixel clipped.
    let mut white = t;
    white.rgb.iter_mut().for_each(|p| *p = [1.0; 3]);
    white.clipped.iter_mut().for_each(|c| *c = [true; 3]);
    let m = err(fit_image(
        &sc,
        0,
        &white,
        Free::default_set(),
        None,
        RenderOptions::default(),
    ));
    assert!(m.contains("clipped"), "{m}");
    assert!(Free::parse("").is_err() && Free::parse("gloss").is_err());
    assert!(phong_fit::image::find_object(&sc, Some("teapot")).is_err());
    assert_eq!(phong_fit::image::find_object(&sc, Some("SPHERE")).expect("by name"), 0);
    // Not a PNG.
    let dir = tempfile::tempdir().expect("tmp");
    let f = dir.path().join("t.png");
    std::fs::write(&f, b"not a png").expect("write");
    assert!(
        matches!(Target::read(&f, Encoding::Linear), Err(phong_fit::FitError::Input(m)) if m.contains("not a PNG"))
    );
}

/// A normalised Blinn-Phong BRDF, as phong's `blinn-phong` normalisation defines it.
fn blinn(kd: f64, ks: f64, s: f64) -> impl Fn([f64; 3], [f64; 3]) -> [f64; 3] {
    move |l, v| {
        let h = {
            let a = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            a.map(|x| x / n)
        };
        let f = kd / PI + ks * (s + 8.0) / (8.0 * PI) * h[2].max(0.0).powf(s);
        [f; 3]
    }
}

/// `(l, v)` of half/difference angles (φ_h = 0).
fn from_half_diff(th: f64, td: f64, pd: f64) -> ([f64; 3], [f64; 3]) {
    let d = [td.sin() * pd.cos(), td.sin() * pd.sin(), td.cos()];
    let l = [
        d[0] * th.cos() + d[2] * th.sin(),
        d[1],
        -d[0] * th.sin() + d[2] * th.cos(),
    ];
    let h = [th.sin(), 0.0, th.cos()];
    let hl = h[0] * l[0] + h[2] * l[2];
    (l, [2.0 * hl * h[0] - l[0], -l[1], 2.0 * hl * h[2] - l[2]])
}

#[test]
fn a_merl_file_written_from_known_parameters_is_fitted_back() {
    let (kd, ks, s) = (0.3, 0.6, 60.0);
    let f = blinn(kd, ks, s);
    let bytes = Merl::encode(|th, td, pd| {
        let (l, v) = from_half_diff(th, td, pd);
        f(l, v)
    });
    assert_eq!(bytes.len(), 12 + 3 * 90 * 90 * 180 * 8);
    let dir = tempfile::tempdir().expect("tmp");
    let file = dir.path().join("blinn.binary");
    std::fs::write(&file, &bytes).expect("write");
    let brdf = Brdf::parse(&format!("merl:{}", file.display())).expect("a MERL file");
    // The lookup returns each bin's value at directions inside the bin.
    let mut rng = Rng(3);
    for _ in 0..200 {
        let (th, td, pd) = (
            rng.next().powi(2) * PI / 2.0 * 0.9,
            rng.next() * PI / 2.0 * 0.9,
            rng.next() * PI,
        );
        let (l, v) = from_half_diff(th, td, pd);
        if l[2] <= 0.05 || v[2] <= 0.05 {
            continue;
        }
        let got = brdf.eval(l, v).expect("measured")[0];
        let want = f(l, v)[0];
        // One θ_h bin apart at most, near the peak the lobe changes fast: 15%.
        assert!(
            (got - want).abs() <= 0.15 * want + 1e-3,
            "θh {th} θd {td} φd {pd}: {got} vs {want}"
        );
    }
    let fit = fit_brdf(&brdf, SpecularModel::BlinnPhong).expect("fit");
    let m = fit.material;
    assert!((f64::from(m.diffuse().r) - kd).abs() < 0.02, "kd {:?}", m.diffuse());
    assert!((f64::from(m.specular().r) - ks).abs() < 0.03, "ks {:?}", m.specular());
    assert!((f64::from(m.shininess()) / s - 1.0).abs() < 0.05, "s {}", m.shininess());
    // Truncated and wrong files.
    std::fs::write(&file, &bytes[..bytes.len() - 8]).expect("write");
    assert!(
        matches!(Brdf::parse(&format!("merl:{}", file.display())), Err(phong_fit::FitError::Input(m)) if m.contains("truncated"))
    );
    let mut wrong = bytes.clone();
    wrong[0] = 45;
    std::fs::write(&file, &wrong).expect("write");
    assert!(Brdf::parse(&format!("merl:{}", file.display())).is_err());
    // Values no measurement has (infinite, NaN, 1e300) are unmeasured, not a panic: a file of
    // nothing else is an input error; a few of them among good values leave the fit as it was.
    for bad in [f64::INFINITY, f64::NAN, 1e300] {
        std::fs::write(&file, Merl::encode(|_, _, _| [bad; 3])).expect("write");
        let brdf = Brdf::parse(&format!("merl:{}", file.display())).expect("a MERL file");
        assert!(
            matches!(
                fit_brdf(&brdf, SpecularModel::BlinnPhong),
                Err(phong_fit::FitError::Input(_))
            ),
            "{bad}"
        );
        let mixed = Merl::encode(|th, td, pd| {
            let (l, v) = from_half_diff(th, td, pd);
            if ((th * 1000.0) as u64).is_multiple_of(7) {
                [bad; 3]
            } else {
                f(l, v)
            }
        });
        std::fs::write(&file, mixed).expect("write");
        let brdf = Brdf::parse(&format!("merl:{}", file.display())).expect("a MERL file");
        let m = fit_brdf(&brdf, SpecularModel::BlinnPhong).expect("fit").material;
        assert!(
            (f64::from(m.diffuse().r) - kd).abs() < 0.02,
            "{bad}: kd {:?}",
            m.diffuse()
        );
    }
}

#[test]
fn a_ggx_lambert_base_is_recovered() {
    let brdf = Brdf::parse("ggx:alpha=0.3,f0=0.04,kd=0.4").expect("spec");
    let fit = fit_brdf(&brdf, SpecularModel::BlinnPhong).expect("fit");
    assert!(
        (f64::from(fit.material.diffuse().r) - 0.4).abs() < 0.05,
        "{:?}",
        fit.material.diffuse()
    );
}

#[test]
fn ggx_exponents_follow_two_over_alpha_squared() {
    // The known approximation s ≈ 2/α² − 2; measured ratios 1.04-1.22 for α from 0.1 to 0.3.
    for alpha in [0.1, 0.15, 0.2, 0.3] {
        let brdf = Brdf::parse(&format!("ggx:alpha={alpha},f0=0.04,kd=0.2")).expect("spec");
        let s = f64::from(
            fit_brdf(&brdf, SpecularModel::BlinnPhong)
                .expect("fit")
                .material
                .shininess(),
        );
        let approx = 2.0 / (alpha * alpha) - 2.0;
        let ratio = s / approx;
        eprintln!("alpha {alpha}: s {s:.1}, 2/α²−2 = {approx:.1}, ratio {ratio:.3}");
        assert!((0.95..1.3).contains(&ratio), "alpha {alpha}: s {s} vs {approx}");
    }
    for bad in [
        "ggx",
        "ggx:alpha=0",
        "ggx:alpha=0.2,f0=x",
        "phong:alpha=0.2",
        "ward:alpha=0.2,kd=1/2",
        "merl:/nonexistent",
    ] {
        assert!(Brdf::parse(bad).is_err(), "{bad}");
    }
}

/// A highlight brighter than the lights allow in [0, 1] and clipped at 255: the target's clipped
/// channels are constraints (at least 254.5/255), not left out, and the colours may pass 1.
/// The specular colour 1.6 and exponent 60 come back (from a noise-free 8-bit target), and the
/// fit says that the specular colour is past 1.
#[test]
fn clipped_highlights_and_colours_past_one_are_fitted() {
    let m = Material::new(
        Color::new(0.1, 0.05, 0.05),
        Color::new(0.5, 0.25, 0.2),
        Color::new(1.6, 1.6, 1.6),
        Color::BLACK,
        60.0,
    )
    .expect("material");
    let sc = scene(lights(0), ShadingOptions::default(), m, Interpolation::Phong);
    let mut rng = Rng(7);
    let t = target(&sc, &mut rng, 0.0);
    let clipped = t.clipped.iter().filter(|c| c.iter().all(|&x| x)).count();
    assert!(clipped > 20, "the highlight is clipped on {clipped} pixels");
    let fit = fit_image(&sc, 0, &t, Free::default_set(), None, RenderOptions::default()).expect("fit");
    let s = fit.material.shininess();
    assert!((s - 60.0).abs() < 0.05 * 60.0, "s = {s}");
    let ks = fit.material.specular().r;
    assert!((ks - 1.6).abs() < 0.05 * 1.6, "specular {ks}");
    assert!(
        fit.notes.iter().any(|n| n.starts_with("specular 1.")),
        "{:?}",
        fit.notes
    );
    assert!(fit.psnr > 45.0, "psnr {}", fit.psnr);
}

/// Targets rendered by a physically based path tracer (Mitsuba 3, `tests/pbr/make_targets.py`:
/// GGX and Beckmann rough plastics, a rough gold conductor, a self-shadowing torus; one and two
/// point lights, direct light only): the fit comes within 0.3 dB of the brute-force best of the
/// same model (`best_by_search`), and on the gold sphere, whose highlight is brighter than
/// lights of 1 make, it says its specular colour is past 1.
#[test]
fn physically_based_targets_are_fitted_as_well_as_brute_force() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/pbr");
    for name in [
        "plastic_ggx_015",
        "plastic_beckmann_030",
        "gold_ggx_020",
        "torus_plastic_ggx_020",
    ] {
        let scene = phong_scene::load(&dir.join(format!("{name}.toml")))
            .expect("scene")
            .scene;
        let t = Target::read(&dir.join(format!("{name}.png")), Encoding::Linear).expect("target");
        let fit = fit_image(&scene, 0, &t, Free::default_set(), None, RenderOptions::default()).expect("fit");
        let best = phong_fit::image::best_by_search(&scene, 0, &t, Free::default_set(), None, RenderOptions::default())
            .expect("search");
        assert!(
            fit.psnr >= best.psnr - 0.3,
            "{name}: the fit's {:.2} dB (s = {}) against the best {:.2} dB (s = {})",
            fit.psnr,
            fit.material.shininess(),
            best.psnr,
            best.shininess
        );
        if name.starts_with("gold") {
            assert!(
                fit.notes.iter().any(|n| n.starts_with("specular")),
                "{name}: {:?}",
                fit.notes
            );
        }
    }
}

/// The brute-force search refuses a target or mask of another size, as the fit does (no
/// index past the image).
#[test]
fn search_refuses_a_target_of_another_size() {
    let sc = scene(
        lights(0),
        ShadingOptions::default(),
        Material::default(),
        Interpolation::Phong,
    );
    let mut small = sc.clone();
    small.image.width = 80;
    let t = target(&small, &mut Rng(3), 0.0);
    let search = |mask: Option<&[bool]>, t: &Target| {
        phong_fit::image::best_by_search(&sc, 0, t, Free::default_set(), mask, RenderOptions::default())
    };
    let e = search(None, &t).err().expect("refused").to_string();
    assert!(e.contains("80x160"), "{e}");
    let full = target(&sc, &mut Rng(3), 0.0);
    let e = search(Some(&[true; 10]), &full).err().expect("refused").to_string();
    assert!(e.contains("mask"), "{e}");
}
