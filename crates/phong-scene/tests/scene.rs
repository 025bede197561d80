//! Scene files: what they build, and every error path with its message and location.

use phong_core::*;
use phong_scene::{Error, parse_scene};
use std::path::Path;

fn parse(src: &str) -> Result<Scene, Error> {
    parse_scene(src, Path::new("scene.toml")).map(|l| l.scene)
}

/// The error message for `src`, which must fail.
fn err(src: &str) -> String {
    match parse(src) {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => e.to_string(),
    }
}

fn assert_err(src: &str, want: &[&str]) {
    let e = err(src);
    for w in want {
        assert!(e.contains(w), "error {e:?} lacks {w:?}");
    }
}

#[test]
fn empty_scene_has_opengl_defaults() {
    let s = parse("").unwrap();
    assert_eq!(
        (s.image.width, s.image.height, s.image.samples),
        (800, 600, Samples::One)
    );
    assert_eq!(s.lighting.ambient(), Color::splat(0.2));
    // No light: one white directional light from the camera (travelling along its view direction).
    assert_eq!(s.lighting.lights().len(), 1);
    assert_eq!(s.lighting.lights()[0].to_light(), Some(-s.camera.forward()));
    assert!(s.objects.is_empty());
    // An object without `[shading]`: the default options, a local viewer.
    let s = parse("[[object]]\nshape = \"cube\"\n").unwrap();
    assert_eq!(s.objects[0].shading.options, ShadingOptions::default());
    assert_eq!(s.objects[0].shading.viewer, Viewer::Local);
}

#[test]
fn objects_materials_and_transforms() {
    let s = parse(
        r#"
[camera]
projection = "orthographic"
height = 4
[materials.clay]
paint = [0.8, 0.5, 0.3]
shininess = 8
[materials.shiny]
base = "gold"
shininess = 100
[[object]]
shape = "sphere"
segments = 16
material = "clay"
position = [1, 2, 3]
scale = 2
[[object]]
shape = "cube"
material = { diffuse = [0.1, 0.2, 0.3] }
rotation = [0, 90, 0]
[[object]]
shape = "torus"
radius = 2
tube = 0.5
material = "Shiny"
"#,
    )
    .unwrap();
    assert!(s.objects.iter().all(|o| o.shading.viewer == Viewer::Infinite));
    let clay = s.objects[0].material;
    assert_eq!(clay.ambient(), Color::new(0.8, 0.5, 0.3));
    assert_eq!(clay.specular(), Color::WHITE);
    // Sphere of radius 2 at (1, 2, 3): every vertex at distance 2.
    for p in s.objects[0].mesh.positions() {
        assert!(((*p - glam::Vec3::new(1.0, 2.0, 3.0)).length() - 2.0).abs() < 1e-5);
    }
    // Inline material: the rest from OpenGL's default material.
    assert_eq!(s.objects[1].material.diffuse(), Color::new(0.1, 0.2, 0.3));
    assert_eq!(s.objects[1].material.ambient(), Color::splat(0.2));
    // base = "gold" with shininess overridden.
    let gold = Material::named("gold").unwrap();
    assert_eq!(s.objects[2].material.diffuse(), gold.diffuse());
    assert_eq!(s.objects[2].material.shininess(), 100.0);
    // Torus radius 2, tube 0.5: x extent 2.5.
    let (lo, hi) = s.objects[2].mesh.bounds().unwrap();
    assert!((hi.x - 2.5).abs() < 1e-4 && (lo.x + 2.5).abs() < 1e-4);
}

#[test]
fn models_and_options() {
    // The `[shading]` section, as the scene's one object gets it.
    let parse = |src: &str| parse(&format!("{src}[[object]]\nshape = \"cube\"\n")).map(|s| s.objects[0].shading);
    let s = parse("[shading]\nmodel = \"phong-lyon\"\nlyon_squarings = 4\nlyon_lambda = \"difference\"\n").unwrap();
    assert_eq!(
        s.options.specular,
        SpecularModel::Lyon {
            squarings: 4,
            lambda: LyonLambda::Difference
        }
    );
    let s = parse("[shading]\nmodel = \"opengl\"\ntwo_sided = true\n").unwrap();
    assert_eq!(s.options, ShadingOptions::opengl(true));
    let s = parse("[shading]\nmodel = \"lambert\"\nnormalization = \"blinn-phong-exact\"\nclamp = false\n").unwrap();
    assert_eq!(s.options.specular, SpecularModel::None);
    assert_eq!(s.options.normalization, Normalization::BlinnPhongExact);
    assert!(!s.options.clamp);
}

#[test]
fn lights() {
    let s = parse(
        r#"
[[light]]
type = "point"
position = [0, 1, 0]
attenuation = [1, 0.5, 0.25]
ambient = [0.1, 0.1, 0.1]
[[light]]
type = "spot"
position = [0, 4, 0]
direction = [0, -1, 0]
cutoff = 25
exponent = 8
color = [1, 0, 0]
"#,
    )
    .unwrap();
    let l = s.lighting.lights();
    assert_eq!(l.len(), 2);
    assert_eq!(l[0].attenuation().unwrap().coefficients(), [1.0, 0.5, 0.25]);
    assert_eq!(l[0].color().ambient(), Color::splat(0.1));
    assert_eq!(l[1].color().diffuse(), Color::new(1.0, 0.0, 0.0));
    assert_eq!(l[1].spot_cone().unwrap().1, 25.0);
}

#[test]
fn syntax_and_type_errors_have_line_column_and_key() {
    assert_err(
        "[image]\nwidth = 800\nheight = \"tall\"\n",
        &[
            "scene.toml:3:10",
            "`height`",
            "must be an integer, got the text \"tall\"",
        ],
    );
    // In the user's words, never serde's ("invalid type: ..., expected f32").
    for (text, says) in [
        (
            "[image]\nbackground = \"red\"\n",
            "`background`: must be a list ([...]), got the text \"red\"",
        ),
        ("[image]\nencoding = 3\n", "`encoding`: must be text in quotes, got 3"),
        (
            "[image]\nantialias = true\n",
            "`antialias`: must be an integer, got true",
        ),
        (
            "[shading]\ntwo_sided = 1\n",
            "`two_sided`: must be true or false, got 1",
        ),
    ] {
        assert_err(text, &[says]);
        let e = parse_scene(text, std::path::Path::new("scene.toml"))
            .err()
            .unwrap()
            .to_string();
        assert!(!e.contains("invalid type") && !e.contains("expected"), "{e}");
    }
    // Inside an inline table, the key inside it, at its column.
    assert_err(
        "[[object]]\nshape = \"sphere\"\nmaterial = { diffuse = [1, 0, 0], shininess = \"high\" }\n",
        &[
            "scene.toml:3:35",
            "`shininess`",
            "must be a number, got the text \"high\"",
        ],
    );
    assert_err(
        "[[object]]\nshape = \"sphere\"\nmaterial = { difuse = [1, 0, 0] }\n",
        &["scene.toml:3:14", "`difuse`", "unknown field `difuse`"],
    );
    assert_err("[image\nwidth = 1\n", &["scene.toml:1:"]);
    assert_err("[image]\nwidht = 800\n", &["scene.toml:2:1", "unknown field `widht`"]);
    assert_err(
        "[[object]]\nshape = \"sphere\"\ncolour = [1, 0, 0]\n",
        &["scene.toml:3:1", "unknown field `colour`"],
    );
    assert_err("[camara]\n", &["scene.toml:1:", "unknown field `camara`"]);
    // An error at a key's start names the key (it used to say only "duplicate key").
    assert_err(
        "[image]\nwidth = 1\nwidth = 2\n",
        &["scene.toml:3:1", "`width`: duplicate key"],
    );
    assert_err("[image]\nwidht = 800\n", &["`widht`: unknown field `widht`"]);
}

#[test]
fn value_errors_have_line_column_and_key() {
    assert_err(
        "[image]\nwidth = 1000000\n",
        &["scene.toml:2:9", "`width`", "from 1 to 16384", "1000000"],
    );
    assert_err("[image]\nheight = 0\n", &["scene.toml:2:10", "`height`"]);
    assert_err(
        "[image]\nantialias = 3\n",
        &["scene.toml:2:13", "`antialias`", "1, 4 or 16"],
    );
    // Each side within its range, the whole past the core's limit of pixels × samples
    // (16384² × 4): reported at the key that made it so, with the core's rule.
    assert_err(
        "[image]\nwidth = 16384\nheight = 16384\nantialias = 16\n",
        &[
            "scene.toml:4:13",
            "`antialias`",
            "16384x16384 with 16 samples",
            "cannot be rendered",
        ],
    );
    assert!(parse("[image]\nwidth = 16384\nheight = 16384\nantialias = 4\n").is_ok());
    assert_err("[image]\nbackground = [1, 2]\n", &["scene.toml:2:14", "`background`"]);
    // Integers past 64 bits, in words; a duplicate key inside an inline table named itself.
    for n in ["99999999999999999999999", "9223372036854775808"] {
        assert_err(
            &format!("[image]\nwidth = {n}\n"),
            &["scene.toml:2:9", "`width`", &format!("{n} is too large")],
        );
    }
    assert_err(
        "[[object]]\nshape = \"sphere\"\nmaterial = { diffuse = [1, 1, 1], diffuse = [0, 0, 0] }\n",
        &["scene.toml:3:35", "`diffuse`: duplicate key"],
    );
    assert_err("[camera]\nfov = 200\n", &["scene.toml:2:7", "`fov`", "(0, 180)"]);
    assert_err("[camera]\nnear = -1\n", &["scene.toml:2:8", "`near`"]);
    assert_err("[camera]\nnear = 5\nfar = 1\n", &["scene.toml:3:7", "`far`"]);
    assert_err("[camera]\nposition = [0, 0, 0]\n", &["scene.toml:2:12", "`camera`"]);
    assert_err(
        "[camera]\nposition = [0, 5, 0]\n",
        &["scene.toml:2:12", "`camera`", "parallel to the view direction"],
    );
    assert_err(
        "[camera]\nposition = [0, 0]\n",
        &["scene.toml:2:12", "`position`", "3 numbers"],
    );
    assert_err(
        "[materials.bad]\nshininess = -1\n",
        &["scene.toml:2:13", "`shininess`", ">= 0", "-1"],
    );
    assert_err(
        "[materials.bad]\ndiffuse = [0.5, -0.1, 0]\n",
        &["scene.toml:2:11", "`diffuse`", ">= 0"],
    );
    assert_err("[materials.bad]\nalpha = 2\n", &["scene.toml:2:9", "`alpha`"]);
    assert_err(
        "[shading]\nambient = [nan, 0, 0]\n",
        &["scene.toml:2:11", "`ambient`", "finite"],
    );
    assert_err(
        "[shading]\nmodel = \"opengl\"\nnormalization = \"phong\"\n",
        &["scene.toml:3:17", "`normalization`"],
    );
}

#[test]
fn misspelled_choices_get_did_you_mean() {
    assert_err(
        "[shading]\nmodel = \"blin-phong\"\n",
        &["scene.toml:2:9", "`model`", "did you mean \"blinn-phong\""],
    );
    assert_err("[shading]\ninterpolation = \"gourad\"\n", &["did you mean \"gouraud\""]);
    assert_err("[shading]\noutput = \"specullar\"\n", &["did you mean \"specular\""]);
    assert_err(
        "[camera]\nprojection = \"ortho\"\n",
        &["`projection`", "\"orthographic\""],
    );
    assert_err(
        "[[light]]\ntype = \"spotlight\"\n",
        &["scene.toml:2:8", "`type`", "\"spot\""],
    );
    assert_err(
        "[[object]]\nshape = \"sphear\"\n",
        &["scene.toml:2:9", "did you mean \"sphere\""],
    );
    assert_err(
        "[[object]]\nshape = \"sphere\"\nmaterial = \"emrald\"\n",
        &["scene.toml:3:12", "`material`", "did you mean emerald"],
    );
    assert_err(
        "[[object]]\nshape = \"sphere\"\nnormals = \"smoth\"\n",
        &["`normals`", "\"smooth\""],
    );
}

#[test]
fn light_errors() {
    assert_err(
        "[[light]]\ntype = \"directional\"\n",
        &["scene.toml:1:1", "`direction`", "needs"],
    );
    assert_err(
        "[[light]]\ntype = \"directional\"\ndirection = [0, 0, 0]\n",
        &["scene.toml:3:13", "`direction`", "non-zero"],
    );
    assert_err(
        "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nattenuation = [0, 0, 1]\n",
        &["scene.toml:4:15", "`attenuation`", "never reaches 0"],
    );
    assert_err(
        "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\ncutoff = 10\n",
        &["`cutoff`", "has no"],
    );
    assert_err(
        "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n",
        &["`cutoff`", "needs"],
    );
    assert_err(
        "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\ncutoff = 120\n",
        &["scene.toml:5:10", "[0, 90]"],
    );
    assert_err(
        "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\ncolor = [1, 1, -1]\n",
        &["scene.toml:4:9", "`color`"],
    );
}

#[test]
fn object_errors() {
    assert_err(
        "[[object]]\nmaterial = \"gold\"\n",
        &["scene.toml:1:1", "`object`", "needs `shape`"],
    );
    assert_err(
        "[[object]]\nshape = \"sphere\"\nsegments = 2\n",
        &["scene.toml:3:12", "`segments`", "from 3"],
    );
    assert_err(
        "[[object]]\nshape = \"sphere\"\nsegments = 100000\n",
        &["`segments`", "4096"],
    );
    assert_err(
        "[[object]]\nshape = \"sphere\"\nradius = 2\n",
        &["scene.toml:3:10", "only a torus"],
    );
    assert_err(
        "[[object]]\nshape = \"sphere\"\nscale = 0\n",
        &["scene.toml:3:9", "`scale`", "non-zero"],
    );
    assert_err("[[object]]\nshape = \"sphere\"\nscale = [1, 2]\n", &["`scale`"]);
    assert_err(
        "[[object]]\nmesh = \"missing.obj\"\n",
        &["scene.toml:2:8", "`mesh`", "file not found", "missing.obj"],
    );
    assert_err(
        "[[object]]\nshape = \"cube\"\nmesh = \"x.obj\"\n",
        &["`mesh`", "not both"],
    );
}

#[test]
fn meshes_load_relative_to_the_scene() {
    let dir = std::env::temp_dir().join(format!("phong-scene-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
    let path = dir.join("s.toml");
    let l = parse_scene("[[object]]\nmesh = \"tri.obj\"\nnormals = \"flat\"\n", &path).unwrap();
    assert_eq!(l.scene.objects.len(), 1);
    assert_eq!(l.scene.objects[0].mesh.corner_normal(0, 0), glam::Vec3::Z);
    let e = parse_scene("[[object]]\nmesh = \"bad.obj\"\n", &path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.obj:3:7: `f`: vertex index 7 is out of range"), "{e}");
    // Through `load`, a missing file is named.
    let e = phong_scene::load(&dir.join("nope.toml")).unwrap_err();
    assert!(e.is_input() && e.to_string().contains("nope.toml"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// `normals = "file"` on a model without normals, and file normals that are zero: normals by
/// angle instead (each unit length), with a warning naming the part.
#[test]
fn unusable_file_normals_fall_back_with_a_warning() {
    let dir = std::env::temp_dir().join(format!("phong-normals-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("bare.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(
        dir.join("zero.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 0\nf 1//1 2//2 3//1\n",
    )
    .unwrap();
    for (mesh, normals, want) in [
        ("bare.obj", "normals = \"file\"\n", "has no normals"),
        ("zero.obj", "", "1 of its 3 file normals are zero"),
    ] {
        let src = format!("[[object]]\nmesh = \"{mesh}\"\n{normals}");
        let loaded = parse_scene(&src, &dir.join("s.toml")).unwrap();
        let m = &loaded.scene.objects[0].mesh;
        assert!(
            m.normals().iter().all(|n| (n.length() - 1.0).abs() < 1e-5),
            "{mesh}: {:?}",
            m.normals()
        );
        assert!(
            loaded.warnings.iter().any(|w| w.contains(mesh) && w.contains(want)),
            "{mesh}: {:?}",
            loaded.warnings
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// One image named by a scene's material and by its OBJ's MTL (and the scene loaded again, as
/// `phong serve` reloads it): decoded once, the texture shared while alive.
#[test]
fn an_image_named_twice_is_decoded_once() {
    let dir = std::env::temp_dir().join(format!("phong-scene-shared-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A 4×4 RGB image unlike any other test's (the sharing is process-wide).
    let mut png = Vec::new();
    let mut enc = png::Encoder::new(&mut png, 4, 4);
    enc.set_color(png::ColorType::Rgb);
    let pixels: Vec<u8> = (0..48u8).map(|i| i.wrapping_mul(37).wrapping_add(11)).collect();
    enc.write_header().unwrap().write_image_data(&pixels).unwrap();
    std::fs::write(dir.join("shared.png"), &png).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nKd 1 1 1\nmap_Kd shared.png\n").unwrap();
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("s.toml"),
        "[[object]]\nshape = \"plane\"\nmaterial = { diffuse_map = \"shared.png\" }\n[[object]]\nmesh = \"m.obj\"\n",
    )
    .unwrap();
    let first = phong_scene::load(&dir.join("s.toml")).unwrap();
    assert_eq!(
        (first.textures.images, first.textures.shared),
        (1, 1),
        "{:?}",
        first.textures
    );
    let map = |l: &phong_scene::Loaded, i: usize| l.scene.objects[i].maps.diffuse.clone().unwrap().texture;
    assert!(std::sync::Arc::ptr_eq(&map(&first, 0), &map(&first, 1)));
    // Loaded again while the first is alive: shared; once it is dropped: decoded anew.
    let again = phong_scene::load(&dir.join("s.toml")).unwrap();
    assert_eq!((again.textures.images, again.textures.shared), (0, 2));
    assert!(std::sync::Arc::ptr_eq(&map(&first, 0), &map(&again, 0)));
    drop((first, again));
    let fresh = phong_scene::load(&dir.join("s.toml")).unwrap();
    assert_eq!((fresh.textures.images, fresh.textures.shared), (1, 1));
    let _ = std::fs::remove_dir_all(dir);
}

/// A material's maps decoded side by side give each image's own decoding; a bump map beside a
/// normal map is not decoded at all, and a missing image is a warning as before.
#[test]
fn a_materials_maps_decode_side_by_side_as_each_alone() {
    let dir = std::env::temp_dir().join(format!("phong-scene-prefetch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let names = ["kd.png", "ks.png", "ke.png", "nm.png", "bump.png"];
    let mut files = Vec::new();
    for (k, name) in names.iter().enumerate() {
        let mut png = Vec::new();
        let mut enc = png::Encoder::new(&mut png, 6, 5);
        enc.set_color(png::ColorType::Rgb);
        let pixels: Vec<u8> = (0..90u8)
            .map(|i| i.wrapping_mul(31 + 2 * k as u8).wrapping_add(k as u8))
            .collect();
        enc.write_header().unwrap().write_image_data(&pixels).unwrap();
        std::fs::write(dir.join(name), &png).unwrap();
        files.push(png);
    }
    std::fs::write(
        dir.join("s.toml"),
        "[[object]]\nshape = \"plane\"\nmaterial = { diffuse_map = \"kd.png\", specular_map = \"ks.png\", \
         emission_map = \"ke.png\", normal_map = \"nm.png\", bump_map = \"bump.png\", ambient_map = \"none.png\" }\n",
    )
    .unwrap();
    let l = phong_scene::load(&dir.join("s.toml")).unwrap();
    assert_eq!(l.textures.images, 4, "{:?}", l.textures);
    let maps = &l.scene.objects[0].maps;
    let alone = |k: usize| phong_scene::decode_texture(&files[k], false).unwrap();
    assert_eq!(*maps.diffuse.as_ref().unwrap().texture, alone(0));
    assert_eq!(*maps.specular.as_ref().unwrap().texture, alone(1));
    assert_eq!(*maps.emission.as_ref().unwrap().texture, alone(2));
    assert_eq!(*maps.normal.as_ref().unwrap().map.texture, alone(3));
    assert!(maps.ambient.is_none());
    let warned = |what: &str| l.warnings.iter().any(|w| w.contains(what));
    assert!(
        warned("none.png") && warned("bump map bump.png is not used"),
        "{:?}",
        l.warnings
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// A value that is none of a key's forms is explained in the scene's words, not serde's.
#[test]
fn untagged_forms_are_explained_in_the_users_words() {
    for (src, key, says) in [
        (
            "[[object]]\nshape = \"sphere\"\nmaterial = { diffuse = \"red\" }\n",
            "`diffuse`",
            "must be a list ([...]), got the text \"red\"",
        ),
        (
            "[[object]]\nshape = \"sphere\"\nmaterial = 5\n",
            "`material`",
            "must be a material's name or a table of its keys",
        ),
        (
            "[[object]]\nshape = \"sphere\"\nscale = \"big\"\n",
            "`scale`",
            "must be a number (uniform) or [x, y, z]",
        ),
    ] {
        let e = phong_scene::parse_scene(src, std::path::Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(key) && e.contains(says), "{e}");
        assert!(!e.contains("untagged") && !e.contains("variant"), "{e}");
    }
}
