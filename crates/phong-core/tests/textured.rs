//! `shade_textured` against `shade` and the OpenGL fixed-function equation written out by
//! hand: GL_MODULATE with GL_SEPARATE_SPECULAR_COLOR.

use phong_core::glam::{Vec2, Vec3};
use phong_core::*;
use proptest::prelude::*;
use std::sync::Arc;

fn color01() -> impl Strategy<Value = Color> {
    (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1.0).prop_map(|(r, g, b)| Color::new(r, g, b))
}

fn unit() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z).normalize_or(Vec3::Y))
}

fn close(a: Color, b: Color, tol: f32) -> bool {
    (a.r - b.r).abs() <= tol && (a.g - b.g).abs() <= tol && (a.b - b.b).abs() <= tol
}

fn setup(a: Color, d: Color, s: Color, e: Color, sh: f32, light_dir: Vec3, light: Color) -> (Material, Lighting) {
    let m = Material::new(a, d, s, e, sh).unwrap();
    let l = Light::directional(-light_dir, LightColor::new(light * 0.3, light, light).unwrap()).unwrap();
    (m, Lighting::new(Color::splat(0.2), vec![l]).unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// Without maps (every texel 1) the textured equation is `shade`'s, clamped or not.
    #[test]
    fn without_maps_it_is_shade(
        a in color01(), d in color01(), s in color01(), e in color01(), sh in 0.0f32..200.0,
        n in unit(), l in unit(), v in unit(), light in color01(), clamp in any::<bool>(),
    ) {
        let (m, lighting) = setup(a, d, s, e, sh, l, light * 3.0);
        let o = ShadingOptions { clamp, ..ShadingOptions::opengl(false) };
        let p = SurfacePoint { position: Vec3::ZERO, normal: n };
        let view = View::Infinite { to_viewer: v };
        let plain = shade(&p, &view, &m, &lighting, &o);
        let tex = shade_textured(&p, &view, &m, &Texels::default(), &lighting, &o);
        prop_assert!(close(plain.color, tex.color, 1e-5), "{:?} vs {:?}", plain.color, tex.color);
        prop_assert!(close(plain.ambient, tex.ambient, 1e-5));
        prop_assert!(close(plain.diffuse, tex.diffuse, 1e-6));
        prop_assert!(close(plain.specular, tex.specular, 1e-6));
    }

    /// With a diffuse map only, under the `opengl` model: OpenGL's
    /// `clamp(clamp(e + A + D)⊗T + clamp(S))`, the terms taken from `shade`.
    #[test]
    fn a_diffuse_map_is_gl_modulate_with_separate_specular(
        a in color01(), d in color01(), s in color01(), e in color01(), sh in 0.0f32..200.0,
        n in unit(), l in unit(), v in unit(), light in color01(), t in color01(),
    ) {
        let (m, lighting) = setup(a, d, s, e, sh, l, light * 2.0);
        let o = ShadingOptions::opengl(false);
        let p = SurfacePoint { position: Vec3::ZERO, normal: n };
        let view = View::Infinite { to_viewer: v };
        let plain = shade(&p, &view, &m, &lighting, &o);
        let texels = Texels { diffuse: [t.r, t.g, t.b, 1.0], ..Texels::default() };
        let tex = shade_textured(&p, &view, &m, &texels, &lighting, &o);
        let primary = (plain.ambient + plain.diffuse).clamp01();
        let gl = (primary * t + plain.specular.clamp01()).clamp01();
        prop_assert!(close(tex.color, gl, 1e-5), "{:?} vs {:?}", tex.color, gl);
    }
}

/// A black texel leaves the highlight: the specular term is added after the texture.
#[test]
fn a_black_texel_keeps_the_highlight() {
    let (m, lighting) = setup(
        Color::splat(0.2),
        Color::splat(0.8),
        Color::splat(0.5),
        Color::BLACK,
        10.0,
        Vec3::Y,
        Color::WHITE,
    );
    let p = SurfacePoint {
        position: Vec3::ZERO,
        normal: Vec3::Y,
    };
    let view = View::Infinite { to_viewer: Vec3::Y };
    let texels = Texels {
        diffuse: [0.0, 0.0, 0.0, 1.0],
        ..Texels::default()
    };
    let s = shade_textured(&p, &view, &m, &texels, &lighting, &ShadingOptions::opengl(false));
    // Light and view along N: R·V = 1, the specular is s_m ⊗ s_l = 0.5; the rest is times 0.
    assert!(close(s.color, Color::splat(0.5), 1e-6), "{:?}", s.color);
    assert_eq!(s.diffuse, Color::BLACK);
}

/// Maps of their own for the ambient, specular, emission and shininess, by hand.
#[test]
fn each_map_modulates_its_term() {
    let m = Material::new(
        Color::splat(0.5),
        Color::splat(0.4),
        Color::splat(1.0),
        Color::splat(0.1),
        8.0,
    )
    .unwrap();
    let l = Light::directional(Vec3::new(0.0, -1.0, 0.0), LightColor::uniform(Color::WHITE).unwrap()).unwrap();
    let lighting = Lighting::new(Color::splat(0.2), vec![l]).unwrap();
    // N·L = 1; V at 60° from N in the plane: R·V = cos 60° = 0.5.
    let v = Vec3::new(3f32.sqrt() / 2.0, 0.5, 0.0);
    let p = SurfacePoint {
        position: Vec3::ZERO,
        normal: Vec3::Y,
    };
    let o = ShadingOptions {
        specular: SpecularModel::Phong,
        clamp: false,
        ..ShadingOptions::default()
    };
    let texels = Texels {
        diffuse: [0.5, 0.5, 0.5, 1.0],
        ambient: Some(Color::new(1.0, 0.0, 0.0)),
        specular: Color::new(0.0, 1.0, 0.0),
        emission: Some(Color::new(0.0, 0.0, 1.0)),
        shininess: 0.5,
        alpha: 1.0,
        normal: None,
        occlusion: None,
    };
    let s = shade_textured(&p, &View::Infinite { to_viewer: v }, &m, &texels, &lighting, &o);
    // A = 0.5·0.2 (the uniform light has no ambient) = 0.1; D = 0.4; S = 0.5^(8·0.5).
    let spec = 0.5f32.powi(4);
    let expected = Color::new(0.4 * 0.5 + 0.1, 0.4 * 0.5 + spec, 0.4 * 0.5 + 0.1);
    assert!(close(s.color, expected, 1e-6), "{:?} vs {expected:?}", s.color);
}

/// A diffuse map through `Maps::sample`: the texel at the coordinates, its alpha
/// multiplied into the material's, and the alpha test.
#[test]
fn an_object_samples_its_maps() {
    // 2×1 texture, top row first: left red (alpha 1/5), right white.
    let texels = [[65535, 0, 0, 13107], [65535; 4]];
    let texture = Arc::new(Texture::new(2, 1, &texels, 16).unwrap());
    let mut map = TextureMap::new(texture);
    map.sampler = Sampler::nearest(Wrap::Clamp);
    let maps = Maps {
        diffuse: Some(map),
        alpha_cutoff: Some(0.5),
        ..Maps::default()
    };
    assert_eq!(
        maps.sample(Vec2::new(0.25, 0.5), Vec2::ZERO, Vec2::ZERO).diffuse,
        [1.0, 0.0, 0.0, 0.2]
    );
    assert_eq!(
        maps.sample(Vec2::new(0.75, 0.5), Vec2::ZERO, Vec2::ZERO).diffuse,
        [1.0; 4]
    );
    let m = Material::default().with_alpha(0.5).unwrap();
    let t = maps.sample(Vec2::new(0.25, 0.5), Vec2::ZERO, Vec2::ZERO);
    let alpha = Maps::alpha(&m, &t);
    assert!((alpha - 0.1).abs() < 1e-6);
    assert!(maps.discards(alpha));
    assert!(!maps.discards(0.5));
}

/// A 1×1 texture of linear RGBA (16 bits).
fn one_texel(c: [f32; 4]) -> TextureMap {
    let t = c.map(|v| (v * 65535.0).round() as u16);
    TextureMap::new(Arc::new(Texture::new(1, 1, &[t], 16).unwrap()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// glTF's metallic-roughness and occlusion textures against the loader's factor mapping
    /// written out per texel: a point with base texel `T`, metalness `m` and roughness `r`
    /// shades as `shade` does the material `diffuse = base·(1 − m)`, `ambient = diffuse·ao`,
    /// `specular = mix(0.04, base, m)`, `s = 2/α² − 2` (`α = r²`), `base = factor⊗T`. The
    /// light is dim, so that no clamp separates the two.
    #[test]
    fn metal_rough_and_occlusion_are_the_factor_mapping_per_texel(
        factor in color01(), t in color01(), mt in 0.0f32..1.0, rt in 0.05f32..1.0, mf in 0.0f32..1.0,
        rf in 0.3f32..1.0, ao in 0.0f32..1.0, strength in 0.0f32..1.0, e in color01(),
        n in unit(), l in unit(), v in unit(),
    ) {
        let mr = MetalRough { map: one_texel([0.0, rt, mt, 1.0]), base_factor: factor, metallic: mf, roughness: rf };
        let maps = Maps {
            diffuse: Some(one_texel([t.r, t.g, t.b, 1.0])),
            metal_rough: Some(mr.clone()),
            occlusion: Some(Occlusion { map: one_texel([ao, 0.5, 0.5, 1.0]), strength }),
            // As the glTF loader gives it: glTF's emission is not modulated by the base colour.
            emission: Some(one_texel([1.0; 4])),
            ..Maps::default()
        };
        let q = |x: f32| (x * 65535.0).round() / 65535.0;
        let (m, r, ao) = (mf * q(mt), rf * q(rt), 1.0 + strength * (q(ao) - 1.0));
        let base = factor * Color::new(q(t.r), q(t.g), q(t.b));
        let a = (r * r).max(1e-9);
        let sh = (2.0 / (a * a) - 2.0).min(10_000.0);
        let d = base * (1.0 - m);
        let plain = Material::new(d * ao, d, Color::splat(0.04 * (1.0 - m)) + base * m, e * 0.1, sh).unwrap();
        let lighting = Lighting::new(
            Color::splat(0.1),
            vec![Light::directional(-l, LightColor::new(Color::splat(0.05), Color::splat(0.3), Color::splat(0.3)).unwrap()).unwrap()],
        ).unwrap();
        let o = ShadingOptions::opengl(false);
        let p = SurfacePoint { position: Vec3::ZERO, normal: n };
        let view = View::Infinite { to_viewer: v };
        let want = shade(&p, &view, &plain, &lighting, &o);
        let texels = maps.sample(Vec2::splat(0.5), Vec2::ZERO, Vec2::ZERO);
        let got = shade_textured(&p, &view, &mr.material(e * 0.1, 1.0), &texels, &lighting, &o);
        prop_assert!(close(want.color, got.color, 2e-5), "{:?} vs {:?}", want.color, got.color);
        prop_assert!(close(want.ambient, got.ambient, 2e-5));
        prop_assert!(close(want.specular, got.specular, 2e-5));
    }
}
