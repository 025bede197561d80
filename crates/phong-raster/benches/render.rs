//! criterion: the 8-lane kernel against the scalar `shade`, and the two CPU paths on the fill
//! scene (see BENCHMARKS.md).

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use phong_core::*;
use phong_raster::internals::{Isa, LANES, Prepared, shade8};
use phong_raster::{RenderOptions, render};
use std::hint::black_box;
use std::path::Path;

fn lighting() -> Lighting {
    let lights = [(-2.0, 2.0, 3.0), (2.0, 2.0, 3.0), (-2.0, -2.0, 3.0), (2.0, -2.0, 3.0)]
        .iter()
        .map(|&(x, y, z)| {
            Light::point(
                Vec3::new(x, y, z),
                LightColor::uniform(Color::splat(0.8)).unwrap(),
                Attenuation::new(1.0, 0.05, 0.02).unwrap(),
            )
            .unwrap()
        })
        .collect();
    Lighting::new(Color::splat(0.2), lights).unwrap()
}

fn kernel(c: &mut Criterion) {
    let lighting = lighting();
    let m = Material::named("polished silver").unwrap();
    let options = ShadingOptions::default();
    let view = View::Local {
        eye: Vec3::new(0.0, 0.0, 3.0),
    };
    let pos: [Vec3; LANES] = std::array::from_fn(|i| Vec3::new(i as f32 * 0.1 - 0.4, 0.2, 0.0));
    let nrm = [Vec3::Z; LANES];
    let prep = Prepared::new(&lighting, &m, &options, view);
    c.bench_function("shade x8 (scalar reference)", |b| {
        b.iter(|| {
            for i in 0..LANES {
                black_box(shade(
                    &SurfacePoint {
                        position: pos[i],
                        normal: nrm[i],
                    },
                    &view,
                    &m,
                    &lighting,
                    &options,
                ));
            }
        })
    });
    c.bench_function("shade8 (baseline build)", |b| {
        b.iter(|| black_box(shade8(Isa::PORTABLE, &prep, black_box(&pos), &nrm)))
    });
    let avx2 = Isa::detect(phong_raster::Kernels::Auto);
    if avx2.is_avx2() {
        c.bench_function("shade8 (AVX2 build)", |b| {
            b.iter(|| black_box(shade8(avx2, &prep, black_box(&pos), &nrm)))
        });
    }
}

fn paths(c: &mut Criterion) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../benches/scenes/fill_4lights.toml");
    let mut scene = phong_scene::load(&p).unwrap().scene;
    scene.image.width = 480;
    scene.image.height = 270;
    let mut g = c.benchmark_group("fill 480x270");
    g.sample_size(20);
    g.bench_function("fast", |b| {
        b.iter(|| render(&scene, &RenderOptions::default()).unwrap())
    });
    let reference = RenderOptions {
        reference: true,
        ..Default::default()
    };
    g.bench_function("reference", |b| b.iter(|| render(&scene, &reference).unwrap()));
    g.finish();
}

criterion_group!(benches, kernel, paths);
criterion_main!(benches);
