//! Test support shared by phong-raster's test files.

use glam::Vec3;
use phong_core::Color;
use phong_raster::Kernels;

/// A small deterministic generator (a 64-bit LCG): the tests' random scenes are reproducible.
pub struct Rng(pub u64);

#[allow(dead_code)] // each test file uses part of it
impl Rng {
    /// Uniform in [0, 1).
    pub fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in [a, b).
    pub fn r(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f()
    }
    /// Each component uniform in [−k, k).
    pub fn v(&mut self, k: f32) -> Vec3 {
        Vec3::new(self.r(-k, k), self.r(-k, k), self.r(-k, k))
    }
    /// Each channel uniform in [0, 1).
    pub fn c(&mut self) -> Color {
        Color::new(self.f(), self.f(), self.f())
    }
}

/// The kernels' builds on this CPU: portable, and AVX2 where the CPU has it. With
/// `PHONG_REQUIRE_AVX2=1` (CI) a CPU without AVX2 and FMA fails instead of testing less.
#[allow(dead_code)] // each test file uses part of it
pub fn isas() -> Vec<phong_raster::internals::Isa> {
    use phong_raster::internals::Isa;
    let avx2 = Isa::detect(phong_raster::Kernels::Auto);
    if !avx2.is_avx2() {
        assert!(
            std::env::var_os("PHONG_REQUIRE_AVX2").is_none_or(|v| v != "1"),
            "PHONG_REQUIRE_AVX2=1 and this CPU has no AVX2 and FMA"
        );
        eprintln!("this CPU has no AVX2 and FMA: the portable build only");
        return vec![Isa::PORTABLE];
    }
    vec![Isa::PORTABLE, avx2]
}

/// One CPU path: the reference, or the fast path in one build of the kernels.
#[allow(dead_code)] // each test file uses part of it
pub struct CpuPath {
    pub name: &'static str,
    pub options: phong_raster::RenderOptions<'static>,
}

#[allow(dead_code)]
impl CpuPath {
    /// `scene` on this path into the `f32` target; where 8 bits are exact for the scene, the
    /// 8-bit target is rendered too and must be the `f32` image's bytes.
    pub fn render(&self, scene: &phong_core::Scene) -> phong_core::Image {
        let image = phong_raster::render(scene, &self.options).unwrap_or_else(|e| panic!("{}: {e}", self.name));
        let mut renderer = phong_raster::Renderer::new();
        if let Some((eight, _)) = renderer.render_8bit(scene, &self.options).unwrap() {
            assert!(
                eight.to_bytes(true) == image.to_bytes(scene.image.encoding, true),
                "{}: the 8-bit target differs from the f32 one",
                self.name
            );
        }
        image
    }
}

/// Every CPU path: the reference, the fast path's portable build and (on a CPU with it) its
/// AVX2 build, the last with 3 threads (images do not depend on the thread count).
#[allow(dead_code)]
pub fn paths() -> Vec<CpuPath> {
    let options = |reference, kernels, threads| phong_raster::RenderOptions {
        reference,
        kernels,
        threads: Some(threads),
        ..Default::default()
    };
    let mut v = vec![
        CpuPath {
            name: "reference",
            options: options(true, Kernels::Auto, 1),
        },
        CpuPath {
            name: "fast, portable",
            options: options(false, Kernels::Portable, 1),
        },
    ];
    if isas().len() > 1 {
        v.push(CpuPath {
            name: "fast, AVX2",
            options: options(false, Kernels::Auto, 3),
        });
    }
    v
}
