//! Golden images: every example scene on every CPU path gives exactly the committed bytes. The
//! CPU's output is deterministic, so the comparison is exact, not within 1/255, with one
//! exception: the AVX2 kernels start their reciprocals and inverse square roots from the
//! hardware's estimates (`vrcpps`, `vrsqrtps`), whose bits differ between CPU makers (Intel's
//! and AMD's tables are not the same), so on a CPU other than the one that blessed them the
//! AVX2 images are checked against the golden PNG within 1/255 instead of by digest. The
//! reference and portable paths use IEEE operations only and are exact everywhere.
//!
//! The paths differ from each other in rounding (the reference's scalar `shade`, the kernels'
//! portable and AVX2 builds), so each has its own golden bytes: `tests/golden/NAME.png` is
//! the default path's image (fast, AVX2; without the scene's labels, which `phong render`
//! draws after the renderer); `digests.txt` holds the
//! FNV-1a digest of each path's 8-bit image. Each path is checked with 1 and 3 threads, into
//! the `f32` and the 8-bit target.
//!
//! After a change meant to alter the images: `PHONG_BLESS=1 cargo test -p phong-raster --test
//! golden` on a CPU with AVX2 rewrites them; say why in the commit.

mod common;

use phong_raster::{Kernels, RenderOptions, Renderer};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn golden(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(file)
}

/// The PNG's size, whether it has alpha, and its bytes.
fn read_png(p: &Path) -> ((u32, u32), bool, Vec<u8>) {
    let file = std::fs::File::open(p).unwrap_or_else(|e| panic!("{}: {e} (PHONG_BLESS=1 writes it)", p.display()));
    let mut r = png::Decoder::new(std::io::BufReader::new(file)).read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    ((info.width, info.height), info.color_type.samples() == 4, buf)
}

/// The example scenes' files, in name order.
fn example_scenes() -> Vec<PathBuf> {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(root().join("examples/scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    scenes
}

/// FNV-1a, 64 bits.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    })
}

#[test]
fn example_scenes_match_their_golden_images() {
    let bless = std::env::var_os("PHONG_BLESS").is_some_and(|v| v == "1");
    let digests_file = golden("digests.txt");
    let mut digests: BTreeMap<String, String> = std::fs::read_to_string(&digests_file)
        .unwrap_or_default()
        .lines()
        .filter_map(|l| l.split_once(' ').map(|(k, v)| (k.to_string(), v.to_string())))
        .collect();
    let scenes = example_scenes();
    assert!(scenes.len() >= 7, "{} example scenes", scenes.len());
    let isas = common::isas();
    let (mut checked, mut pngs, mut estimated) = (0, 0, 0);
    for path in &scenes {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let scene = phong_scene::load(path).unwrap().scene;
        let alpha = scene.image.background[3] < 1.0;
        // The paths: the reference, and the fast path in each build.
        let mut paths = vec![("reference".to_string(), true, Kernels::Auto)];
        paths.extend(isas.iter().map(|isa| {
            let build = if isa.is_avx2() { "avx2" } else { "portable" };
            let kernels = if isa.is_avx2() {
                Kernels::Auto
            } else {
                Kernels::Portable
            };
            (format!("fast-{build}"), false, kernels)
        }));
        for (label, reference, kernels) in paths {
            let key = format!("{name}/{label}");
            let mut first: Option<Vec<u8>> = None;
            for threads in [1, 3] {
                let options = RenderOptions {
                    threads: Some(threads),
                    reference,
                    kernels,
                    ..Default::default()
                };
                let what = format!("{key}, {threads} threads");
                let bytes = phong_raster::render(&scene, &options)
                    .unwrap()
                    .to_bytes(scene.image.encoding, alpha);
                if let Some(f) = &first {
                    assert!(bytes == *f, "{what}: differs from 1 thread");
                }
                let mut renderer = Renderer::new();
                if let Some((image8, _)) = renderer.render_8bit(&scene, &options).unwrap() {
                    assert!(
                        image8.to_bytes(alpha) == bytes,
                        "{what}: the 8-bit target differs from f32"
                    );
                }
                first.get_or_insert(bytes);
            }
            let bytes = first.expect("rendered");
            let digest = format!("{:016x}", fnv1a(&bytes));
            if bless {
                digests.insert(key.clone(), digest.clone());
            }
            let want = digests
                .get(&key)
                .unwrap_or_else(|| panic!("{key}: no digest (PHONG_BLESS=1 writes it)"));
            // The AVX2 images: exact where this CPU's estimates are the blessing CPU's, else
            // within 1/255 of the golden PNG (checked below).
            let estimates_differ = label == "fast-avx2" && &digest != want;
            if !estimates_differ {
                assert_eq!(&digest, want, "{key}: the image differs from its golden digest");
            }
            checked += 1;
            if label == "fast-avx2" {
                let png = golden(&format!("{name}.png"));
                if bless {
                    let image = phong_raster::render(&scene, &RenderOptions::default()).unwrap();
                    std::fs::write(&png, phong_scene::encode_png(&image, scene.image.encoding).unwrap()).unwrap();
                }
                let (size, png_alpha, want) = read_png(&png);
                assert_eq!(
                    (size, png_alpha),
                    ((scene.image.width, scene.image.height), alpha),
                    "{name}"
                );
                if estimates_differ {
                    let worst = bytes.iter().zip(&want).map(|(a, b)| a.abs_diff(*b)).max();
                    assert!(
                        bytes.len() == want.len() && worst <= Some(1),
                        "{name}: the image differs from {} by up to {worst:?}/255",
                        png.display()
                    );
                    estimated += 1;
                } else {
                    assert!(bytes == want, "{name}: the image differs from {}", png.display());
                }
                pngs += 1;
            }
        }
    }
    if bless {
        let text: String = digests.iter().map(|(k, v)| format!("{k} {v}\n")).collect();
        std::fs::write(&digests_file, text).unwrap();
    }
    eprintln!(
        "{checked} golden digests and {pngs} golden PNGs matched ({estimated} AVX2 images within 1/255: \
         this CPU's estimates differ from the blessing CPU's)"
    );
}

/// The shading kernels' wide-register build (their AVX2 code compiled with AVX-512VL, so that
/// LLVM has 32 vector registers: `Isa::wide`) draws the AVX2 build's images bit for bit: every
/// example scene and the textured benchmark scenes, each at 320×180 with 1 and 3 threads,
/// every channel's `f32`. (Textured forms without a wide build, such as normal maps or
/// Gouraud, run the AVX2 build in both: they guard a wide build added later.) Skipped, saying
/// so, on a CPU without AVX-512F, VL, BW and DQ.
#[test]
fn wide_registers_draw_the_avx2_images() {
    if !phong_raster::internals::Isa::detect(phong_raster::Kernels::Auto).wide() {
        eprintln!("skipped: this CPU has no AVX-512F, VL, BW and DQ");
        return;
    }
    let mut scenes = example_scenes();
    for name in [
        "sphere_100k_textured_1",
        "sphere_100k_textured_maps_1",
        "sphere_100k_normal_1",
        "sphere_100k_shininess_1",
        "sphere_100k_gouraud_textured_1",
        "fill_4lights",
        "fill_4lights_textured",
    ] {
        scenes.push(root().join(format!("benches/scenes/{name}.toml")));
    }
    for path in &scenes {
        let mut scene = phong_scene::load(path).unwrap().scene;
        (scene.image.width, scene.image.height) = (320, 180);
        for threads in [1, 3] {
            let image = |no_avx512| {
                let options = RenderOptions {
                    threads: Some(threads),
                    kernels: if no_avx512 { Kernels::Avx2 } else { Kernels::Auto },
                    ..Default::default()
                };
                assert_eq!(
                    phong_raster::kernels(&options),
                    if no_avx512 {
                        "AVX2 kernels"
                    } else {
                        "AVX2 kernels (AVX-512 registers)"
                    }
                );
                let image = phong_raster::render(&scene, &options).unwrap();
                image
                    .pixels()
                    .iter()
                    .flatten()
                    .map(|c| c.to_bits())
                    .collect::<Vec<u32>>()
            };
            // Compared in f32, bit for bit (a rounding apart rarely changes an 8-bit value).
            assert!(
                image(false) == image(true),
                "{}, {threads} threads: the wide build's image differs",
                path.display()
            );
        }
    }
}
