//! Models as people have them: OBJ as it is in the wild, glTF, and the view of a model alone.
//! Files are written here byte by byte (so what they hold is known independently of the
//! readers), and the real models of `../shared/models/` are read where they are.

use base64::Engine;
use glam::{DVec3, Vec2, Vec3};
use phong_scene::{Axis, Error, ModelFile, ModelOptions, ViewName, load_with};

/// The parts of the model at `path`, its warnings added to `warnings`.
fn load_model(path: &std::path::Path, warnings: &mut Vec<String>) -> Result<Vec<phong_scene::ModelPart>, Error> {
    let model = ModelFile::read(path)?;
    warnings.extend(model.warnings);
    Ok(model.parts)
}

use std::path::{Path, PathBuf};

/// A fresh folder for one test's files, removed when the test ends (passed or failed).
struct Dir(PathBuf);

impl std::ops::Deref for Dir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Dir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn dir(tag: &str) -> Dir {
    let d = std::env::temp_dir().join(format!("phong-models-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    Dir(d)
}

fn write(d: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = d.join(name);
    if let Some(parent) = p.parent() {
        std::fs::create_dir_all(parent).unwrap();
    }
    std::fs::write(&p, bytes).unwrap();
    p
}

/// `../shared/models/`, or `None` (the test is skipped) where this checkout has none, unless
/// `PHONG_REQUIRE_MODELS` is set (CI sets it).
fn shared() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    if p.is_dir() {
        Some(p)
    } else {
        assert!(
            std::env::var_os("PHONG_REQUIRE_MODELS").is_none(),
            "PHONG_REQUIRE_MODELS is set but {} is missing",
            p.display()
        );
        eprintln!("skipped: {} is missing", p.display());
        None
    }
}

/// Twice the area of the triangles of every part (|Σ cross| per triangle, summed).
fn area(parts: &[phong_scene::ModelPart]) -> f64 {
    parts
        .iter()
        .map(|p| {
            (0..p.mesh.triangles().len())
                .map(|t| {
                    let [a, b, c] = p.mesh.corners(t).map(|v| v.as_dvec3());
                    (b - a).cross(c - a).length()
                })
                .sum::<f64>()
        })
        .sum()
}

/// An L-shaped hexagon written from its reflex corner (tobj's fan would fill the notch), and a
/// concave 64-gon from another project (assimp's ring): the triangles cover exactly the
/// polygon's area (the shoelace formula), with no triangle facing the other way.
#[test]
fn concave_polygons_are_triangulated_exactly() {
    let d = dir("concave");
    let obj = write(
        &d,
        "l.obj",
        b"v 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4 5 6\n",
    );
    let parts = load_model(&obj, &mut Vec::new()).unwrap();
    assert_eq!(parts[0].mesh.triangles().len(), 4);
    assert!((area(&parts) / 2.0 - 3.0).abs() < 1e-6, "{}", area(&parts) / 2.0);
    for t in 0..4 {
        let [a, b, c] = parts[0].mesh.corners(t);
        assert!((b - a).cross(c - a).z > 0.0, "triangle {t} is wound backwards");
    }
    let Some(shared) = shared() else { return };
    let ring = shared.join("assimp/OBJ/concave_polygon.obj");
    let parts = load_model(&ring, &mut Vec::new()).unwrap();
    // The polygon's area by Newell's formula on the file's own vertices.
    let text = std::fs::read_to_string(&ring).unwrap();
    let v: Vec<DVec3> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            DVec3::new(x[0], x[1], x[2])
        })
        .collect();
    let face: Vec<usize> = text
        .lines()
        .find_map(|l| l.strip_prefix("f "))
        .unwrap()
        .split_whitespace()
        .map(|t| t.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
        .collect();
    let newell: DVec3 = (0..face.len())
        .map(|i| v[face[i]].cross(v[face[(i + 1) % face.len()]]))
        .sum();
    let want = newell.length();
    let got = area(&parts);
    assert!((got - want).abs() < 1e-4 * want, "triangles {got}, polygon {want}");
    // So the test tells: a fan from the first vertex (what tobj did) covers a different area
    // (|Σ cross| of its triangles, the hole and overlaps counted).
    let fan: f64 = (1..face.len() - 1)
        .map(|i| (v[face[i]] - v[face[0]]).cross(v[face[i + 1]] - v[face[0]]).length())
        .sum();
    assert!(
        (fan - want).abs() > 0.01 * want,
        "a fan covers {fan}, the polygon {want}"
    );
    let _ = std::fs::remove_dir_all(d);
}

/// Numbers as C's strtod reads them, `w` ignored, several MTL libraries on one line with
/// escaped spaces, a backslash path, a quoted name, `Tr` as the complement of `d`.
#[test]
fn obj_as_it_is_in_the_wild() {
    let d = dir("wild");
    write(&d, "a b.mtl", b"newmtl spaced\nKd 0.25 0.5 0.75\n");
    write(&d, "sub/c.mtl", b"newmtl sub\nKd 1 0 0\nTr 0.25\n");
    write(&d, "q.mtl", b"newmtl quoted\nKd 0 1 0\nd 0.5\nTr 0.9\n");
    let obj = write(
        &d,
        "wild.obj",
        b"mtllib missing.mtl a\\ b.mtl sub\\c.mtl\nmtllib \"q.mtl\"\n\
          v .8e-1 -.7e+2 1.e-3 2.0\nv 3.1+e2 0 0\nv 0 1e+01 0\n\
          usemtl spaced\nf 1 2 3\nusemtl sub\nf 1 3 2\nusemtl quoted\nf 2 1 3\n",
    );
    let mut w = Vec::new();
    let parts = load_model(&obj, &mut w).unwrap();
    let p = parts[0].mesh.positions();
    assert!(p.contains(&Vec3::new(0.08, -70.0, 0.001)), "{p:?}");
    assert!(p.contains(&Vec3::new(3.1, 0.0, 0.0)), "{p:?}");
    assert!(p.contains(&Vec3::new(0.0, 10.0, 0.0)), "{p:?}");
    assert!(
        w.iter()
            .any(|w| w.contains("wild.obj:4: numbers with trailing characters")),
        "{w:?}"
    );
    assert!(w.iter().any(|w| w.contains("missing.mtl not found")), "{w:?}");
    let find = |r: f32| parts.iter().find_map(|p| p.material.filter(|m| m.diffuse().r == r));
    let spaced = parts
        .iter()
        .find_map(|p| p.material.filter(|m| m.diffuse().g == 0.5))
        .unwrap();
    assert_eq!(spaced.diffuse().b, 0.75);
    assert_eq!(find(1.0).unwrap().alpha(), 0.75, "Tr 0.25 is d 0.75");
    let translucent = parts.iter().find(|p| p.material.is_some_and(|m| m.diffuse().r == 1.0));
    assert!(translucent.is_some_and(|p| p.maps.blend), "a material of d < 1 blends");
    let quoted = parts
        .iter()
        .find_map(|p| p.material.filter(|m| m.diffuse().g == 1.0))
        .unwrap();
    assert_eq!(quoted.alpha(), 0.5, "d wins over Tr");
    let _ = std::fs::remove_dir_all(d);
}

/// Faces with fewer than 3 vertices are skipped and texture or normal indices that refer to
/// nothing are dropped, with warnings; a file of lines alone is refused, saying so; a vertex
/// index out of range and a NaN stay errors at their line and column.
#[test]
fn broken_records_are_skipped_or_refused_at_their_line() {
    let d = dir("broken");
    let obj = write(
        &d,
        "b.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1//1 2//1 3//1\nl 1 2\n",
    );
    let mut w = Vec::new();
    let parts = load_model(&obj, &mut w).unwrap();
    assert_eq!(parts.iter().map(|p| p.mesh.triangles().len()).sum::<usize>(), 1);
    assert!(!parts[0].has_normals);
    assert!(
        w.iter()
            .any(|w| w.contains("1 faces with fewer than 3 vertices skipped")),
        "{w:?}"
    );
    assert!(
        w.iter()
            .any(|w| w.contains("3 texture or normal indices refer to nothing")),
        "{w:?}"
    );
    let lines = write(&d, "l.obj", b"v 0 0 0\nv 1 0 0\nl 1 2\n");
    let e = load_model(&lines, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("no faces") && e.contains("1 line (`l`)"), "{e}");
    let bad = write(&d, "bad.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    let e = load_model(&bad, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("bad.obj:4:7: `f`: vertex index 4 is out of range"), "{e}");
    let nan = write(&d, "nan.obj", b"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    let e = load_model(&nan, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("nan.obj:2:5: `v`: \"nan\" is not a finite number"), "{e}");
    let _ = std::fs::remove_dir_all(d);
}

/// A model far from the origin for its size is re-centred in f64: a triangle with 1 mm detail
/// at 10 000 km keeps its shape exactly (f32 alone would put its corners 1 m apart), and a
/// scene that places it without `fit` puts it back where the file says.
#[test]
fn far_models_keep_their_detail() {
    let d = dir("far");
    let obj = write(
        &d,
        "far.obj",
        b"v 10000000.000 20000000.000 5\nv 10000000.001 20000000.000 5\nv 10000000.000 20000000.001 5\nf 1 2 3\n",
    );
    let parts = load_model(&obj, &mut Vec::new()).unwrap();
    let origin = parts[0].origin;
    assert!(
        (origin - DVec3::new(10000000.0005, 20000000.0005, 5.0)).length() < 1e-6,
        "{origin}"
    );
    let [a, b, c] = parts[0].mesh.corners(0);
    assert!(((b - a).length() - 0.001).abs() < 1e-7 && ((c - a).length() - 0.001).abs() < 1e-7);
    // In a scene without `fit`, the file's coordinates (as f32 can hold them).
    write(&d, "s.toml", b"[[object]]\nmesh = \"far.obj\"\n");
    let scene = phong_scene::load(&d.join("s.toml")).unwrap().scene;
    let p = scene.objects[0].mesh.positions()[0];
    assert!((p - Vec3::new(1e7, 2e7, 5.0)).length() < 4.0, "{p}");
    // With `fit`, centred with a bounding sphere of radius 1.
    write(&d, "f.toml", b"[[object]]\nmesh = \"far.obj\"\nfit = true\n");
    let scene = phong_scene::load(&d.join("f.toml")).unwrap().scene;
    let (lo, hi) = scene.objects[0].mesh.bounds().unwrap();
    assert!(((hi - lo).length() - 2.0).abs() < 1e-5 && ((lo + hi) * 0.5).length() < 1e-5);
    let _ = std::fs::remove_dir_all(d);
}

/// A model alone: the same model framed alike whatever its size and offset (the camera in the
/// fitted frame is the same); culling for a closed model, two-sided lighting for an open one;
/// z up for a bust on a flat base; the named views and `--camera` place the camera as asked.
#[test]
fn a_model_alone_is_framed_whatever_its_size_and_offset() {
    let d = dir("frame");
    // A closed tetrahedron, wound outward.
    let tet = |k: f64, o: f64| {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut s = String::new();
        for p in v {
            s += &format!("v {} {} {}\n", p[0] * k + o, p[1] * k + o, p[2] * k + o);
        }
        s + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    };
    let mut cameras = Vec::new();
    for (name, k, o) in [
        ("unit", 1.0, 0.0),
        ("tiny", 1e-6, 0.0),
        ("huge", 1e30, 0.0),
        ("far", 1.0, 1e8),
    ] {
        let p = write(&d, &format!("{name}.obj"), tet(k, o).as_bytes());
        let loaded = load_with(&p, &ModelOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let c = loaded.scene.camera;
        assert!(c.eye().is_finite(), "{name}");
        assert!(
            loaded.notes.iter().any(|n| n.contains("back faces culled")),
            "{name}: {:?}",
            loaded.notes
        );
        cameras.push((name, c.eye(), c.target()));
        // Every vertex is in front of the camera, inside the near and far planes.
        for v in loaded.scene.objects[0].mesh.positions() {
            let depth = (*v - c.eye()).dot((c.target() - c.eye()).normalize());
            assert!(depth > c.near() && depth < c.far(), "{name}: {v} at {depth}");
        }
    }
    for (name, p, t) in &cameras[1..] {
        assert!(
            (*p - cameras[0].1).length() < 1e-4 && (*t - cameras[0].2).length() < 1e-4,
            "{name}: {p} {t}"
        );
    }
    // Open: one triangle is drawn two-sided, seen from the side its face looks to.
    // (At 1e30 too: the analysis is in f64, where f32 cross products would overflow.)
    for (name, text) in [
        ("tri.obj", "v 0 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n"),
        ("hugetri.obj", "v 0 0 0\nv 0 1e30 0\nv 0 0 1e30\nf 1 2 3\n"),
    ] {
        let tri = write(&d, name, text.as_bytes());
        let loaded = load_with(&tri, &ModelOptions::default()).unwrap();
        assert!(
            loaded.notes.iter().any(|n| n.contains("two-sided")),
            "{:?}",
            loaded.notes
        );
        let normal = Vec3::X; // (0,1,0) × (0,0,1)
        let c = loaded.scene.camera;
        assert!(
            (c.eye() - c.target()).normalize().dot(normal) > 0.5,
            "{name}: {:?}",
            loaded.notes
        );
    }
    // Named views: `top` looks down the up axis; `--camera` in the file's coordinates.
    let far = d.join("far.obj");
    let top = load_with(
        &far,
        &ModelOptions {
            view: Some(ViewName::Top),
            up: Some(Axis::Z),
            ..ModelOptions::default()
        },
    )
    .unwrap()
    .scene
    .camera;
    let dir_ = (top.eye() - top.target()).normalize();
    assert!(dir_.dot(Vec3::Z) > 0.999, "{dir_}");
    let cam = load_with(
        &far,
        &ModelOptions {
            camera: Some((DVec3::new(1e8 + 0.5, 1e8 + 0.5, 1e8 + 10.0), DVec3::new(1e8, 1e8, 1e8))),
            ..ModelOptions::default()
        },
    )
    .unwrap()
    .scene
    .camera;
    let dir_ = (cam.eye() - cam.target()).normalize();
    let want = Vec3::new(0.5, 0.5, 10.0).normalize();
    assert!(dir_.dot(want) > 0.9999, "{dir_} vs {want}");
    let _ = std::fs::remove_dir_all(d);
}

/// The shared real models: Nefertiti's scan stands z up on a flat base; Spot faces −z and is
/// closed; the Cornell box is open, drawn two-sided and seen from its open side.
#[test]
fn real_models_are_viewed_sensibly() {
    let Some(shared) = shared() else { return };
    let load = |p: &str| load_with(&shared.join(p), &ModelOptions::default()).unwrap();
    let nef = load("common-3d/nefertiti.obj");
    assert!(nef.notes.iter().any(|n| n.starts_with("up axis z")), "{:?}", nef.notes);
    let up = nef.scene.camera.view_from_world().row(1).truncate();
    assert!(up.dot(Vec3::Z) > 0.9, "{up}");
    let spot = load("spot/spot_triangulated.obj");
    assert!(spot.notes.iter().any(|n| n.starts_with("front -z")), "{:?}", spot.notes);
    assert!(
        spot.notes.iter().any(|n| n.contains("back faces culled")),
        "{:?}",
        spot.notes
    );
    let c = spot.scene.camera;
    assert!(c.eye().z < c.target().z, "the camera is on Spot's -z side");
    let cb = load("tinyobjloader/models/cornell_box.obj");
    assert!(cb.notes.iter().any(|n| n.contains("two-sided")), "{:?}", cb.notes);
    assert!(cb.scene.objects.iter().all(|o| o.shading.options.two_sided));
    let c = cb.scene.camera;
    assert!(c.eye().z < c.target().z, "the camera is at the box's open side (-z)");
}

/// Every model of `../shared/models/` loads, or fails with an error naming the file for the
/// ones that are truly broken (a vertex index out of range or zero, a NaN, no faces at all).
#[test]
fn every_shared_model_loads_or_says_why() {
    let Some(shared) = shared() else { return };
    let broken = [
        "invalid-relative-texture-index.obj",
        "invalid-relative-vertex-index.obj",
        "issue-140-zero-face-idx.obj",
        "test-nan.obj",
        "invalid-face-definition.obj",
        "issue-356-leading-spaces-newmtl.obj",
        "line-prim.obj",
        "points-prim.obj",
    ];
    let mut stack = vec![shared];
    let mut seen = 0;
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let ext = p.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
            if !matches!(ext.as_deref(), Some("obj" | "gltf" | "glb" | "ply" | "stl")) {
                continue;
            }
            seen += 1;
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            match load_with(&p, &ModelOptions::default()) {
                Ok(l) => {
                    assert!(!broken.contains(&name.as_str()), "{name} loaded");
                    assert!(l.scene.triangle_count() > 0, "{name}");
                    assert!(l.scene.camera.eye().is_finite(), "{name}");
                }
                Err(e) => {
                    assert!(broken.contains(&name.as_str()), "{name}: {e}");
                    assert!(e.is_input() && e.to_string().contains(&name), "{name}: {e}");
                }
            }
        }
    }
    assert!(seen >= 70, "{seen} models");
}

/// A glTF file written here: a buffer as a data URI holding a quad's 4 positions, a strip and
/// a fan of its 4 indices, a node tree that moves, scales and mirrors it, materials, a camera
/// and a light.
fn gltf_json(extra_nodes: &str, required: &str, bad_index: bool) -> String {
    let mut bin = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]] {
        for x in p {
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    // The strip's indices, then the fan's (around the quad).
    let idx: [u16; 8] = if bad_index {
        [0, 1, 2, 9, 0, 1, 3, 2]
    } else {
        [0, 1, 2, 3, 0, 1, 3, 2]
    };
    for i in idx {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    format!(
        r#"{{"asset": {{"version": "2.0"}}, {required}
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 8}},
                  {{"buffer": 0, "byteOffset": 56, "byteLength": 8}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 4, "type": "SCALAR"}},
    {{"bufferView": 2, "componentType": 5123, "count": 4, "type": "SCALAR"}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.8, 0.4, 0.2, 1.0], "metallicFactor": 0.25, "roughnessFactor": 0.5}},
                  "emissiveFactor": [0.1, 0.0, 0.0]}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": 5, "material": 0}},
                             {{"attributes": {{"POSITION": 0}}, "indices": 2, "mode": 6}}]}}],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.5, "znear": 0.1}}}}],
  "nodes": [{{"children": [1]}}, {{"mesh": 0, "translation": [10, 0, 0], "scale": [2, 2, -2]}},
            {{"camera": 0, "translation": [0, 0, 20]}}{extra_nodes}],
  "scenes": [{{"nodes": [0, 2]}}], "scene": 0}}"#,
        len = bin.len()
    )
}

/// glTF: strips and fans, node transforms (a mirroring scale flips the winding back), the
/// metallic-roughness mapping, glTF's camera; a cycle, an index out of range, a missing
/// buffer file and a required extension phong does not read are errors naming the file.
#[test]
fn gltf_geometry_materials_and_errors() {
    let d = dir("gltf");
    let p = write(&d, "quad.gltf", gltf_json("", "", false).as_bytes());
    let model = ModelFile::read(&p).unwrap();
    assert_eq!(model.parts.len(), 2);
    for part in &model.parts {
        assert_eq!(part.mesh.triangles().len(), 2);
        // World = T(10,0,0)·S(2,2,-2): the quad spans x 10..12, y 0..2; area 4 per part.
        let (lo, hi) = part.mesh.bounds().unwrap();
        let shift = part.origin.as_vec3();
        assert_eq!(
            (lo + shift, hi + shift),
            (Vec3::new(10.0, 0.0, 0.0), Vec3::new(12.0, 2.0, 0.0))
        );
        assert!((area(std::slice::from_ref(part)) / 2.0 - 4.0).abs() < 1e-5);
        // Every triangle faces the same way: +z in the file, mirrored by z -> -z, winding
        // flipped back, so its normal (by winding) is -z... as drawn by the file: n·z < 0.
        for t in 0..2 {
            let [a, b, c] = part.mesh.corners(t);
            assert!((b - a).cross(c - a).z < 0.0, "triangle {t}");
        }
    }
    // base (0.8, 0.4, 0.2), metallic 0.25, roughness 0.5: diffuse = base·0.75, specular =
    // 0.04 + (base − 0.04)·0.25, α = 0.25, s = 2/α² − 2 = 30.
    let m = model.parts[0].material.unwrap();
    let close = |a: f32, b: f32| (a - b).abs() < 1e-6;
    assert!(close(m.diffuse().r, 0.6) && close(m.diffuse().g, 0.3) && close(m.diffuse().b, 0.15));
    assert!(close(m.specular().r, 0.23) && close(m.specular().g, 0.13) && close(m.specular().b, 0.08));
    assert!(close(m.shininess(), 30.0) && close(m.emission().r, 0.1));
    assert!(model.parts[1].material.is_none(), "no material: OpenGL's default");
    let cam = model.camera.unwrap();
    assert_eq!(cam.position, DVec3::new(0.0, 0.0, 20.0));
    assert!((cam.fov_deg.unwrap() - 0.5f32.to_degrees()).abs() < 1e-4);
    // The model alone is seen through the file's camera.
    let loaded = load_with(&p, &ModelOptions::default()).unwrap();
    assert!(
        loaded.notes.iter().any(|n| n.contains("the file's camera")),
        "{:?}",
        loaded.notes
    );
    // Its materials are single-sided (glTF's default): back faces culled, as the format says,
    // though the quad is open; a double-sided material draws them.
    assert!(
        loaded.notes.iter().any(|n| n.contains("single-sided")),
        "{:?}",
        loaded.notes
    );
    assert!(!loaded.scene.objects[0].shading.options.two_sided);
    let two = write(
        &d,
        "two.gltf",
        gltf_json("", "", false)
            .replace("\"emissiveFactor\"", "\"doubleSided\": true, \"emissiveFactor\"")
            .as_bytes(),
    );
    let loaded = load_with(&two, &ModelOptions::default()).unwrap();
    assert!(loaded.scene.objects[0].shading.options.two_sided, "{:?}", loaded.notes);
    let fail = |name: &str, text: String| {
        let p = write(&d, name, text.as_bytes());
        let e = load_model(&p, &mut Vec::new()).unwrap_err();
        assert!(e.is_input() && e.to_string().contains(name), "{e}");
        e.to_string()
    };
    let e = fail(
        "cycle.gltf",
        gltf_json(r#", {"children": [4]}, {"children": [3]}"#, "", false)
            .replace("\"nodes\": [0, 2]", "\"nodes\": [0, 2, 3]"),
    );
    assert!(e.contains("cycle"), "{e}");
    // A chain of 20 000 nodes, each the child of the one before, the last with the mesh:
    // read (each node visited once; a path kept per node would make it quadratic).
    let chain: String = (3..20_003)
        .map(|i| format!(r#", {{"children": [{}]}}"#, i + 1))
        .chain([r#", {"mesh": 0}"#.to_string()])
        .collect();
    let deep = write(
        &d,
        "deep.gltf",
        gltf_json(&chain, "", false)
            .replace("\"nodes\": [0, 2]", "\"nodes\": [3]")
            .as_bytes(),
    );
    let parts = load_model(&deep, &mut Vec::new()).unwrap();
    assert_eq!(parts.len(), 2);
    // An accessor index past the accessors (gltf-json's validation panicked on it).
    let e = fail(
        "accessor.gltf",
        gltf_json("", "", false).replace("\"POSITION\": 0}, \"indices\": 1", "\"POSITION\": 7}, \"indices\": 1"),
    );
    assert!(e.contains("names accessor 7, but the file has 3"), "{e}");
    // Signed indices (the gltf crate's reader took them for unreachable and panicked).
    let e = fail(
        "signed.gltf",
        gltf_json("", "", false).replace(
            r#"{"bufferView": 1, "componentType": 5123"#,
            r#"{"bufferView": 1, "componentType": 5122"#,
        ),
    );
    assert!(e.contains("not unsigned integers"), "{e}");
    // A byteStride shorter than a position (the gltf crate's reader panicked on it).
    let e = fail(
        "stride.gltf",
        gltf_json("", "", false).replace(
            r#"{"buffer": 0, "byteOffset": 0, "byteLength": 48}"#,
            r#"{"buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 4}"#,
        ),
    );
    assert!(e.contains("byteStride 4 is shorter than an element (12 bytes)"), "{e}");
    let e = fail("range.gltf", gltf_json("", "", true));
    assert!(e.contains("index 9 is out of range"), "{e}");
    let e = fail(
        "draco.gltf",
        gltf_json(
            "",
            r#""extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],"#,
            false,
        ),
    );
    assert!(
        e.contains("KHR_draco_mesh_compression") && e.contains("decompress"),
        "{e}"
    );
    let mut missing = gltf_json("", "", false);
    let start = missing.find("data:").unwrap();
    let end = start + missing[start..].find('"').unwrap();
    missing.replace_range(start..end, "gone.bin");
    let e = fail("missing.gltf", missing);
    assert!(e.contains("gone.bin"), "{e}");
    let _ = std::fs::remove_dir_all(d);
}

/// The shared glTF samples: the textured boxes (24 vertices, 12 triangles; textures named in
/// a warning), the two-cylinder engine's many parts, and the cameras sample's camera.
#[test]
fn shared_gltf_samples() {
    let Some(shared) = shared() else { return };
    let g = shared.join("assimp/glTF2");
    for f in [
        "BoxTextured-glTF/BoxTextured.gltf",
        "BoxTextured-glTF-Binary/BoxTextured.glb",
        "BoxTextured-glTF-Embedded/BoxTextured.gltf",
        "BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf",
    ] {
        let mut w = Vec::new();
        let parts = load_model(&g.join(f), &mut w).unwrap();
        let tris: usize = parts.iter().map(|p| p.mesh.triangles().len()).sum();
        assert_eq!(tris, 12, "{f}");
        // The Cesium logo (a 211×211 PNG, external, embedded or in the GLB) is the diffuse map.
        let map = parts[0]
            .maps
            .diffuse
            .as_ref()
            .unwrap_or_else(|| panic!("{f}: no diffuse map: {w:?}"));
        assert_eq!((map.texture.width(), map.texture.height()), (211, 211), "{f}");
        assert!(parts[0].mesh.has_uvs(), "{f}");
        assert!(!w.iter().any(|w| w.contains("Texture")), "{f}: {w:?}");
    }
    // assimp's box with two coordinate sets: the metallic-roughness texture on TEXCOORD_1, read
    // (no warning), the base colour on TEXCOORD_0.
    let mut w = Vec::new();
    let parts = load_model(&g.join("BoxTexcoords-glTF/boxTexcoords.gltf"), &mut w).unwrap();
    let (mesh, maps) = (&parts[0].mesh, &parts[0].maps);
    assert!(w.is_empty(), "{w:?}");
    assert_eq!(
        (mesh.uvs().len(), mesh.uvs1().len()),
        (mesh.positions().len(), mesh.positions().len())
    );
    assert_ne!(mesh.uvs(), mesh.uvs1());
    assert_eq!(
        (
            maps.diffuse.as_ref().map(|m| m.set),
            maps.metal_rough.as_ref().map(|m| m.map.set)
        ),
        (Some(0), Some(1))
    );
    let engine = load_model(
        &g.join("2CylinderEngine-glTF-Binary/2CylinderEngine.glb"),
        &mut Vec::new(),
    )
    .unwrap();
    assert!(engine.len() > 20, "{} parts", engine.len());
    let cams = ModelFile::read(&g.join("cameras/Cameras.gltf")).unwrap();
    assert!(cams.camera.is_some());
}

/// Transparency as files mean it: an MTL's `d 0.5` (and `Tr 0.75` where there is no `d`) is a
/// blended material of alpha 0.5 (0.25); `d 1` is opaque; glTF's `alphaMode: BLEND` blends,
/// `OPAQUE` does not; a scene material blends only with `blend = true`.
#[test]
fn transparency_is_blending() {
    let d = dir("blend");
    write(
        &d,
        "t.mtl",
        b"newmtl half\nKd 1 0 0\nd 0.5\nnewmtl tr\nTr 0.75\nnewmtl solid\nd 1\n",
    );
    let obj =
        b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl half\nf 1 2 3\nusemtl tr\nf 1 2 3\nusemtl solid\nf 1 2 3\n";
    let p = write(&d, "t.obj", obj);
    let parts = load_model(&p, &mut Vec::new()).unwrap();
    let got: Vec<(f32, bool)> = parts
        .iter()
        .map(|p| (p.material.unwrap().alpha(), p.maps.blend))
        .collect();
    assert_eq!(got, [(0.5, true), (0.25, true), (1.0, false)]);
    for (mode, blend) in [("BLEND", true), ("OPAQUE", false)] {
        let json = gltf_json("", "", false).replace(
            r#""emissiveFactor": [0.1, 0.0, 0.0]}"#,
            &format!(r#""emissiveFactor": [0.1, 0.0, 0.0], "alphaMode": "{mode}"}}"#),
        );
        let p = write(&d, &format!("{mode}.gltf"), json.as_bytes());
        let parts = load_model(&p, &mut Vec::new()).unwrap();
        assert_eq!(parts[0].maps.blend, blend, "{mode}");
    }
    let scene = |key: &str| {
        let text = format!("[[object]]\nshape = \"cube\"\nmaterial = {{ alpha = 0.5{key} }}\n");
        phong_scene::parse_scene(&text, Path::new("s.toml")).unwrap().scene
    };
    assert!(!scene("").objects[0].blends(), "alpha alone: OpenGL without GL_BLEND");
    assert!(scene(", blend = true").objects[0].blends());
}

/// Vertex colours: an OBJ whose every `v` has `x y z r g b`, a PLY's `red green blue` bytes,
/// glTF's COLOR_0; read where the part has no material (then a white material: they are its
/// ambient and diffuse colours); an OBJ where not every vertex has one is warned about.
#[test]
fn vertex_colours_are_read() {
    let d = dir("colours");
    let p = write(&d, "c.obj", b"v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n");
    let parts = load_model(&p, &mut Vec::new()).unwrap();
    let mut c: Vec<[f32; 3]> = parts[0].mesh.colors().iter().map(|c| c.to_array()).collect();
    c.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(c, [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]);
    assert_eq!(parts[0].material.unwrap().diffuse().to_array(), [1.0; 3]);
    let p = write(&d, "partial.obj", b"v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let mut w = Vec::new();
    let parts = load_model(&p, &mut w).unwrap();
    assert!(parts[0].mesh.colors().is_empty());
    assert!(w.iter().any(|w| w.contains("vertex colours")), "{w:?}");
    // A colour that is no finite number: the colours are dropped with a warning, the
    // positions kept (the model is drawn).
    for bad in ["nan", "inf", "-inf"] {
        let text = format!("v 0 0 0 1 0 0\nv 1 0 0 0 {bad} 0\nv 0 1 0 0 0 1\nf 1 2 3\n");
        let p = write(&d, "nan.obj", text.as_bytes());
        let mut w = Vec::new();
        let parts = load_model(&p, &mut w).unwrap_or_else(|e| panic!("{bad}: {e}"));
        assert!(parts[0].mesh.colors().is_empty(), "{bad}");
        assert_eq!(parts[0].mesh.positions().len(), 3, "{bad}");
        assert!(
            w.iter()
                .any(|w| w.contains("vertex colours are not used: 1 colour values are not finite")),
            "{bad}: {w:?}"
        );
    }
    let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\n\
end_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 51\n3 0 1 2\n";
    let p = write(&d, "c.ply", ply);
    let parts = load_model(&p, &mut Vec::new()).unwrap();
    let c: Vec<[f32; 3]> = parts[0].mesh.colors().iter().map(|c| c.to_array()).collect();
    assert_eq!(c, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.2]]);
}

/// Models made on another machine: an MTL named in another case, a texture named by an
/// absolute Windows path and one in another case, a glTF's buffer and image moved into a
/// folder: each file is found by its name, with a warning naming what was read; the maps are
/// the images' (their texels compared).
#[test]
fn files_named_on_another_machine_are_found() {
    let d = dir("moved");
    let red = phong_core::Image::new(2, 2, [1.0, 0.0, 0.0, 1.0]).unwrap();
    let green = phong_core::Image::new(2, 2, [0.0, 1.0, 0.0, 1.0]).unwrap();
    write(
        &d,
        "Maps/Red.PNG",
        &phong_scene::encode_png(&red, phong_core::Encoding::Linear).unwrap(),
    );
    write(
        &d,
        "maps/green.png",
        &phong_scene::encode_png(&green, phong_core::Encoding::Linear).unwrap(),
    );
    write(
        &d,
        "Q.MTL",
        b"newmtl m\nmap_Kd C:\\Users\\bob\\model\\red.png\nmap_Ks MAPS/GREEN.PNG\n",
    );
    let obj = write(
        &d,
        "q.obj",
        b"mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n",
    );
    let mut w = Vec::new();
    let parts = load_model(&obj, &mut w).unwrap();
    let texel = |m: &Option<phong_core::TextureMap>| {
        let t = &m.as_ref().expect("a map").texture;
        t.sample(
            &phong_core::Sampler::nearest(phong_core::Wrap::Repeat),
            Vec2::new(0.5, 0.5),
            0.0,
        )
    };
    assert_eq!(texel(&parts[0].maps.diffuse), [1.0, 0.0, 0.0, 1.0]);
    assert_eq!(texel(&parts[0].maps.specular), [0.0, 1.0, 0.0, 1.0]);
    assert_eq!(w.len(), 3, "{w:?}");
    for (name, read) in [
        ("q.mtl", "Q.MTL"),
        ("red.png", "Maps/Red.PNG"),
        ("GREEN.PNG", "maps/green.png"),
    ] {
        assert!(
            w.iter()
                .any(|w| w.contains(name) && w.contains(read) && w.contains("not there as written")),
            "{name}: {w:?}"
        );
    }
    // A glTF whose buffer and image were moved into a folder.
    let mut bin = Vec::new();
    for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        bin.extend(v.iter().flat_map(|x| x.to_le_bytes()));
    }
    for t in [[0f32, 0.0], [1.0, 0.0], [0.0, 1.0]] {
        bin.extend(t.iter().flat_map(|x| x.to_le_bytes()));
    }
    write(&d, "data/Tri.bin", &bin);
    let gltf = write(
        &d,
        "t.gltf",
        br#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"material":0}]}],
"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
"textures":[{"source":0}],"images":[{"uri":"red.png"}],
"buffers":[{"uri":"tri.bin","byteLength":60}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}]}"#,
    );
    let mut w = Vec::new();
    let parts = load_model(&gltf, &mut w).unwrap();
    assert_eq!(parts.len(), 1);
    assert!(parts[0].maps.diffuse.is_some(), "{w:?}");
    assert!(
        w.iter().any(|w| w.contains("tri.bin") && w.contains("data/Tri.bin")),
        "{w:?}"
    );
    assert!(
        w.iter().any(|w| w.contains("red.png") && w.contains("Maps/Red.PNG")),
        "{w:?}"
    );
}

/// Normal maps from each source: a scene's `normal_map` (with `normal_scale` and
/// `normal_green`), an MTL's `norm`; the object gets MikkTSpace tangents (a plane's: +x).
#[test]
fn normal_maps_are_read_with_tangents() {
    let d = dir("normals");
    let flat = phong_core::Image::new(2, 2, [0.5, 0.5, 1.0, 1.0]).unwrap();
    let png = phong_scene::encode_png(&flat, phong_core::Encoding::Linear).unwrap();
    write(&d, "n.png", &png);
    let scene = write(
        &d,
        "s.toml",
        b"[[object]]\nshape = \"plane\"\nmaterial = { normal_map = \"n.png\", normal_scale = 0.5, normal_green = \"down\" }\n",
    );
    let loaded = load_with(&scene, &ModelOptions::default()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let o = &loaded.scene.objects[0];
    let n = o.maps.normal.as_ref().expect("a normal map");
    assert_eq!((n.scale, n.green_down), (0.5, true));
    assert!(!o.mesh.tangents().is_empty());
    for t in o.mesh.tangents() {
        assert!((t.truncate() - Vec3::X).length() < 1e-5 && t.w == 1.0, "{t}");
    }
    write(&d, "q.mtl", b"newmtl m\nnorm n.png\n");
    let obj = write(
        &d,
        "q.obj",
        b"mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n",
    );
    let parts = load_model(&obj, &mut Vec::new()).unwrap();
    assert!(parts[0].maps.normal.is_some());
}

/// glTF's metallic-roughness and occlusion textures: read with their factors (the material
/// becomes the one the map scales: diffuse the base factor, specular white, shininess 1) and
/// the occlusion's strength; the emissive factor kept apart from the base colour by a white
/// emission map; no warning.
#[test]
fn gltf_metal_rough_and_occlusion_textures_are_read() {
    let d = dir("gltf_pbr");
    for (name, rgb) in [
        ("base.png", [200u8, 100, 50]),
        ("mr.png", [0, 128, 255]),
        ("ao.png", [64, 0, 0]),
    ] {
        solid_png(&d, name, rgb);
    }
    let b64 = triangle_with_uvs(&[]);
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": 60, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 24}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}],
  "images": [{{"uri": "base.png"}}, {{"uri": "mr.png"}}, {{"uri": "ao.png"}}],
  "textures": [{{"source": 0}}, {{"source": 1}}, {{"source": 2}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.5, 1.0, 1.0, 1.0], "metallicFactor": 0.75,
                  "roughnessFactor": 0.5, "baseColorTexture": {{"index": 0}}, "metallicRoughnessTexture": {{"index": 1}}}},
                  "occlusionTexture": {{"index": 2, "strength": 0.5}}, "emissiveFactor": [0.1, 0.0, 0.0]}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "material": 0}}]}}],
  "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#
    );
    let p = write(&d, "pbr.gltf", json.as_bytes());
    let mut w = Vec::new();
    let parts = load_model(&p, &mut w).unwrap();
    assert!(w.is_empty(), "{w:?}");
    let (maps, m) = (&parts[0].maps, parts[0].material.unwrap());
    let mr = maps.metal_rough.as_ref().expect("a metallic-roughness map");
    assert_eq!(
        (mr.base_factor.to_array(), mr.metallic, mr.roughness),
        ([0.5, 1.0, 1.0], 0.75, 0.5)
    );
    assert_eq!(
        mr.map.texture.texel(0, 0, 0),
        [0.0, 128.0 / 255.0, 1.0, 1.0],
        "linear, not sRGB"
    );
    assert_eq!(m.diffuse().to_array(), [0.5, 1.0, 1.0]);
    assert_eq!((m.specular().to_array(), m.shininess()), ([1.0; 3], 1.0));
    assert_eq!(m.emission().to_array(), [0.1, 0.0, 0.0]);
    let ao = maps.occlusion.as_ref().expect("an occlusion map");
    assert_eq!((ao.strength, ao.map.texture.texel(0, 1, 1)[0]), (0.5, 64.0 / 255.0));
    let e = maps.emission.as_ref().expect("the emission kept apart");
    assert_eq!(e.texture.texel(0, 0, 0), [1.0; 4]);
    // At a texel: metalness 0.75·1, roughness 0.5·128/255, occlusion 1 + 0.5·(64/255 − 1).
    let t = maps.sample(Vec2::splat(0.5), Vec2::ZERO, Vec2::ZERO);
    // The diffuse texel multiplies the material's diffuse (the base factor); the specular
    // texel is the specular colour itself (the material's is white).
    let texel = ((200.0f32 / 255.0 + 0.055) / 1.055).powf(2.4);
    assert!((t.diffuse[0] - texel * 0.25).abs() < 1e-3, "{:?}", t.diffuse);
    assert!(
        (t.specular.r - (0.04 * 0.25 + 0.5 * texel * 0.75)).abs() < 1e-3,
        "{:?}",
        t.specular
    );
    let a = (0.5f32 * 128.0 / 255.0).powi(2);
    assert!(
        (t.shininess - (2.0 / (a * a) - 2.0)).abs() < 1e-2 * t.shininess,
        "{}",
        t.shininess
    );
    assert!((t.occlusion.unwrap() - (1.0 + 0.5 * (64.0 / 255.0 - 1.0))).abs() < 1e-6);
}

/// glTF's TANGENT: read where the primitive has normals and a normal map, by the node's matrix
/// (a mirroring node flips `w`), and kept with the file's normals instead of MikkTSpace's; a
/// primitive without it gets MikkTSpace's: `T` along `+u` (`+x` here), and `B = w·(N × T)`
/// along OpenGL's `+v`, which is glTF's `−v`, here `−y`: `w = −1` (what the format's own
/// definition, `B = w·(N × T)` pointing up the image, gives too).
#[test]
fn gltf_tangents_are_read() {
    let d = dir("gltf_tangents");
    solid_png(&d, "n.png", [128, 128, 255]);
    let gltf = |tangents: bool, scale: f32| {
        let mut bin = Vec::new();
        let floats: [&[f32]; 4] = [
            &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
            &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
            &[0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0],
        ];
        for x in floats.concat() {
            bin.extend_from_slice(&x.to_le_bytes());
        }
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        let tangent = if tangents { r#", "TANGENT": 3"# } else { "" };
        format!(
            r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": 120, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 36}},
                  {{"buffer": 0, "byteOffset": 72, "byteLength": 24}}, {{"buffer": 0, "byteOffset": 96, "byteLength": 48}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC4"}}],
  "images": [{{"uri": "n.png"}}], "textures": [{{"source": 0}}],
  "materials": [{{"normalTexture": {{"index": 0}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2{tangent}}}, "material": 0}}]}}],
  "nodes": [{{"mesh": 0, "scale": [{scale}, 1, 1]}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#
        )
    };
    for (tangents, scale, want) in [
        (true, 1.0, [0.0, 1.0, 0.0, -1.0]),
        (true, -1.0, [0.0, 1.0, 0.0, 1.0]),
        (false, 1.0, [1.0, 0.0, 0.0, -1.0]),
    ] {
        write(&d, "t.gltf", gltf(tangents, scale).as_bytes());
        let scene = write(&d, "s.toml", b"[[object]]\nmesh = \"t.gltf\"\nfit = false\n");
        let loaded = load_with(&scene, &ModelOptions::default()).unwrap();
        let mesh = &loaded.scene.objects[0].mesh;
        assert!(!mesh.tangents().is_empty(), "tangents {tangents}");
        for t in mesh.tangents() {
            assert!(
                (*t - glam::Vec4::from_array(want)).abs().max_element() < 1e-6,
                "TANGENT {tangents}, scale {scale}: {t} vs {want:?}"
            );
        }
    }
}

/// A glTF primitive without normals gets flat normals, as the specification requires ("client
/// implementations MUST calculate flat normals"): a strip of two triangles folded 35° along
/// their shared edge, well inside the 60° crease that would smooth it, has on each triangle's
/// corners that triangle's facet normal (the cross product of its edges, by hand below), in a
/// scene and as a model alone; `normals = "angle"` asks for the smooth ones, and `"file"` says
/// the file has none and gives flat ones.
#[test]
fn gltf_without_normals_is_flat() {
    let d = dir("gltf_flat");
    let mut bin = Vec::new();
    for x in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.5] {
        bin.extend_from_slice(&x.to_le_bytes());
    }
    for i in [0u16, 1, 2, 1, 3, 2] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    let gltf = format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": 60, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0.5]}},
    {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#
    );
    let model = write(&d, "fold.gltf", gltf.as_bytes());
    // (1,0,0) × (0,1,0) and (0,1,0.5) × (−1,1,0), normalised.
    let facets = [Vec3::Z, Vec3::new(-0.5, -0.5, 1.0) / 1.5f32.sqrt()];
    // Each corner's normal against the facet normal of its triangle's drawn positions, and
    // that facet one of the two above (not checked for the model alone, which may be turned).
    let corners_are_flat = |mesh: &phong_core::Mesh, turned: bool| {
        let pos = mesh.positions();
        assert_eq!(mesh.triangles().len(), 2);
        for (f, t) in mesh.triangles().iter().enumerate() {
            let [a, b, c] = t.map(|i| pos[i as usize]);
            let facet = (b - a).cross(c - a).normalize();
            if !turned {
                assert!(facets.iter().any(|f| (facet - *f).length() < 1e-6), "{facet}");
            }
            for k in 0..3 {
                let n = mesh.corner_normal(f, k);
                assert!((n - facet).length() < 1e-6, "corner normal {n} on a facet {facet}");
            }
        }
    };
    for (normals, flat) in [
        ("", true),
        ("normals = \"file\"\n", true),
        ("normals = \"angle\"\n", false),
    ] {
        let toml = format!("[[object]]\nmesh = \"fold.gltf\"\nfit = false\n{normals}");
        let scene = write(&d, "s.toml", toml.as_bytes());
        let loaded = load_with(&scene, &ModelOptions::default()).unwrap();
        let mesh = &loaded.scene.objects[0].mesh;
        if flat {
            corners_are_flat(mesh, false);
        } else {
            // Smooth across the fold: the shared corners' normals lie between the facets'.
            let shared = mesh
                .normals()
                .iter()
                .filter(|n| n.dot(facets[0]) < 0.999 && n.dot(facets[1]) < 0.999)
                .count();
            assert!(shared >= 2, "{normals}: {:?}", mesh.normals());
        }
        let said = loaded
            .warnings
            .iter()
            .any(|w| w.contains("no normals for it: normals computed flat"));
        assert_eq!(said, normals.contains("file"), "{normals}: {:?}", loaded.warnings);
    }
    let alone = load_with(&model, &ModelOptions::default()).unwrap();
    corners_are_flat(&alone.scene.objects[0].mesh, true);
}

/// glTF's second texture coordinate set: each texture reads the set its `texCoord` (or its
/// KHR_texture_transform's `texCoord`) names, both sets read with v flipped to OpenGL's; the
/// normal texture's set is the mesh's first (its tangents are made from it); a texture on a
/// third set (TEXCOORD_2) is dropped with a warning.
#[test]
fn gltf_second_texture_coordinate_set_is_read() {
    let d = dir("gltf_texcoord1");
    solid_png(&d, "t.png", [200, 100, 50]);
    // The helper's triangle and first set (set0), then the second set.
    let set0 = [[0.0f32, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let set1 = [[0.25f32, 0.5], [0.75, 0.5], [0.25, 1.0]];
    let b64 = triangle_with_uvs(
        &set1
            .as_flattened()
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect::<Vec<u8>>(),
    );
    let flipped = |s: [[f32; 2]; 3]| s.map(|[u, v]| Vec2::new(u, 1.0 - v)).to_vec();
    let gltf = |material: &str| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["KHR_texture_transform"],
  "buffers": [{{"byteLength": 84, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 24}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": 24}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}}],
  "images": [{{"uri": "t.png"}}],
  "textures": [{{"source": 0}}],
  "materials": [{material}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}}, "material": 0}}]}}],
  "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#
        )
    };
    // Base colour on set 0; occlusion on set 1; emission on set 0 but moved to set 1 by its
    // transform; metallic-roughness on set 2.
    let p = write(
        &d,
        "sets.gltf",
        gltf(
            r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                "metallicRoughnessTexture": {"index": 0, "texCoord": 2}},
              "occlusionTexture": {"index": 0, "texCoord": 1},
              "emissiveTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}}}"#,
        )
        .as_bytes(),
    );
    let mut w = Vec::new();
    let parts = load_model(&p, &mut w).unwrap();
    let (mesh, maps) = (&parts[0].mesh, &parts[0].maps);
    assert_eq!(
        (mesh.uvs().to_vec(), mesh.uvs1().to_vec()),
        (flipped(set0), flipped(set1))
    );
    assert_eq!(maps.diffuse.as_ref().map(|m| m.set), Some(0));
    assert_eq!(maps.occlusion.as_ref().map(|m| m.map.set), Some(1));
    assert_eq!(maps.emission.as_ref().map(|m| m.set), Some(1));
    assert!(maps.metal_rough.is_none());
    assert!(
        w.len() == 1 && w[0].contains("third texture coordinate set") && w[0].contains("1 textures"),
        "{w:?}"
    );
    // A normal texture on set 1: that set is the mesh's first, the base colour's its second.
    let p = write(
        &d,
        "normal.gltf",
        gltf(r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "normalTexture": {"index": 0, "texCoord": 1}}"#)
            .as_bytes(),
    );
    let mut w = Vec::new();
    let parts = load_model(&p, &mut w).unwrap();
    let (mesh, maps) = (&parts[0].mesh, &parts[0].maps);
    assert_eq!(
        (mesh.uvs().to_vec(), mesh.uvs1().to_vec()),
        (flipped(set1), flipped(set0))
    );
    assert_eq!(maps.diffuse.as_ref().map(|m| m.set), Some(1));
    assert_eq!(maps.normal.as_ref().map(|n| n.map.set), Some(0));
    assert!(w.is_empty(), "{w:?}");
}

/// MTL files as exporters write them: a non-numeric `Ni` (not used) is a warning at the
/// MTL's own file and line and the library is still read; `Tr 1` with no `d` in every material
/// would make the model vanish, so it is read as the opacity, with a warning, while `Tr 1` in
/// one material of two keeps its meaning (transparent); `Ns 0` (or no `Ns`) with `Ks` above 0
/// is read as no highlight, with a warning naming the materials, and `Ns 10` is kept.
#[test]
fn mtl_values_exporters_write() {
    let d = dir("mtl-exporters");
    let obj = |mtl: &str| format!("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl {mtl}\nf 1 2 3\n");
    let load = |mtl_text: &str, used: &str| {
        write(&d, "m.mtl", mtl_text.as_bytes());
        let p = write(&d, "m.obj", obj(used).as_bytes());
        let mut w = Vec::new();
        let parts = load_model(&p, &mut w).unwrap_or_else(|e| panic!("{mtl_text}: {e}"));
        (parts[0].material.expect("a material"), w)
    };
    let (m, w) = load("newmtl a\nKd 0.5 0.25 0.125\nNi abc\n", "a");
    assert_eq!(m.diffuse().to_array(), [0.5, 0.25, 0.125], "the library is read");
    assert!(
        w.iter()
            .any(|w| w.contains("m.mtl:3:") && w.contains("\"abc\" is not a finite number")),
        "{w:?}"
    );
    let (m, w) = load("newmtl a\nKd 1 0 0\nTr 1\nnewmtl b\nKd 0 1 0\nTr 1\n", "a");
    assert_eq!(m.alpha(), 1.0);
    assert!(w.iter().any(|w| w.contains("read as the opacity")), "{w:?}");
    let (m, w) = load("newmtl a\nKd 1 0 0\nTr 1\nnewmtl b\nKd 0 1 0\nd 1\n", "a");
    assert_eq!(m.alpha(), 0.0, "one material transparent by Tr: as the file says");
    assert!(!w.iter().any(|w| w.contains("opacity")), "{w:?}");
    let (m, w) = load("newmtl shiny\nKd 1 1 1\nKs 0.5 0.5 0.5\nNs 0\n", "shiny");
    assert_eq!(m.specular().to_array(), [0.0; 3]);
    assert!(
        w.iter()
            .any(|w| w.contains("\"shiny\"") && w.contains("no specular highlight")),
        "{w:?}"
    );
    let (m, w) = load("newmtl kept\nKd 1 1 1\nKs 0.5 0.5 0.5\nNs 10\n", "kept");
    assert_eq!(m.specular().to_array(), [0.5; 3]);
    assert_eq!(m.shininess(), 10.0);
    assert!(!w.iter().any(|w| w.contains("highlight")), "{w:?}");
}

/// A bottle as a scanner gives it: a surface of revolution `length` long and 0.07 wide, with a
/// rounded bottom (no flat base) and a neck, its axis along `axis` (0 x, 1 y, 2 z); positions
/// and triangles.
fn bottle(axis: usize, length: f32) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let (rings, around) = (24, 16);
    // Radius along the axis: a hemisphere, the body, a shoulder, the neck.
    let radius = |t: f32| {
        let r = 0.035;
        let z = t * length;
        if z < r {
            (r * r - (r - z) * (r - z)).max(0.0).sqrt()
        } else if t < 0.7 {
            r
        } else if t < 0.85 {
            r - (t - 0.7) / 0.15 * 0.02
        } else {
            0.015
        }
    };
    let mut positions = Vec::new();
    for i in 0..=rings {
        let t = i as f32 / rings as f32;
        for j in 0..around {
            let a = j as f32 / around as f32 * std::f32::consts::TAU;
            let (u, v, w) = (radius(t) * a.cos(), radius(t) * a.sin(), t * length);
            // The axis coordinate `w`, the other two in order (a right-handed frame).
            let mut p = [0.0; 3];
            p[axis] = w;
            p[(axis + 1) % 3] = u;
            p[(axis + 2) % 3] = v;
            positions.push(Vec3::from_array(p));
        }
    }
    let mut tris = Vec::new();
    for i in 0..rings {
        for j in 0..around {
            let (a, b) = (i * around + j, i * around + (j + 1) % around);
            let (c, d) = (a + around, b + around);
            tris.push([a, b, d]);
            tris.push([a, d, c]);
        }
    }
    (positions, tris)
}

/// A long, thin model scanned z up (a bottle 0.22 long and 0.07 wide, no flat base) is seen z
/// up, and the same model y up is seen y up, from OBJ, PLY (ASCII and binary) and STL (ASCII
/// and binary) files alike; a model long along y or x, or a flat one, is not taken as z up.
#[test]
fn long_thin_models_stand_on_their_long_axis() {
    let d = dir("bottle");
    let files = |name: &str, (positions, tris): &(Vec<Vec3>, Vec<[usize; 3]>)| -> Vec<PathBuf> {
        let mut obj = String::new();
        for p in positions {
            obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        for t in tris {
            obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        let header = |format: &str| {
            format!(
                "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
                 element face {}\nproperty list uchar int vertex_indices\nend_header\n",
                positions.len(),
                tris.len()
            )
        };
        let mut ascii_ply = header("ascii");
        for p in positions {
            ascii_ply += &format!("{} {} {}\n", p.x, p.y, p.z);
        }
        for t in tris {
            ascii_ply += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
        }
        let mut binary_ply = header("binary_little_endian").into_bytes();
        for p in positions {
            for c in p.to_array() {
                binary_ply.extend(c.to_le_bytes());
            }
        }
        for t in tris {
            binary_ply.push(3);
            for &i in t {
                binary_ply.extend((i as i32).to_le_bytes());
            }
        }
        let mut ascii_stl = String::from("solid bottle\n");
        let mut binary_stl = vec![0u8; 80];
        binary_stl.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            let [a, b, c] = t.map(|i| positions[i]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            ascii_stl += &format!("facet normal {} {} {}\nouter loop\n", n.x, n.y, n.z);
            for v in [a, b, c] {
                ascii_stl += &format!("vertex {} {} {}\n", v.x, v.y, v.z);
            }
            ascii_stl += "endloop\nendfacet\n";
            for v in [n, a, b, c] {
                for x in v.to_array() {
                    binary_stl.extend(x.to_le_bytes());
                }
            }
            binary_stl.extend([0, 0]);
        }
        ascii_stl += "endsolid bottle\n";
        vec![
            write(&d, &format!("{name}.obj"), obj.as_bytes()),
            write(&d, &format!("{name}.ply"), ascii_ply.as_bytes()),
            write(&d, &format!("{name}_bin.ply"), &binary_ply),
            write(&d, &format!("{name}.stl"), ascii_stl.as_bytes()),
            write(&d, &format!("{name}_bin.stl"), &binary_stl),
        ]
    };
    let up_of = |path: &Path| {
        let loaded = load_with(path, &ModelOptions::default()).unwrap();
        let note = loaded.notes.iter().find(|n| n.starts_with("up axis")).cloned();
        let up = loaded.scene.camera.view_from_world().row(1).truncate();
        (note.unwrap_or_default(), up)
    };
    for (name, axis, length, want) in [
        ("z_up", 2, 0.22, Vec3::Z),
        ("y_up", 1, 0.22, Vec3::Y),
        // Long along x: lying, seen y up.
        ("x_long", 0, 0.22, Vec3::Y),
        // Not long: a squat jar z up has no flat base either, and stays y up.
        ("squat", 2, 0.1, Vec3::Y),
    ] {
        for path in files(name, &bottle(axis, length)) {
            let (note, up) = up_of(&path);
            assert!(up.dot(want) > 0.9, "{}: up {up}, want {want} ({note})", path.display());
            if want == Vec3::Z {
                assert!(note.contains("long along z"), "{}: {note}", path.display());
            }
        }
    }
}

/// The default rig of a model alone lights every face the camera sees: for every unit normal
/// facing the camera (more than 5° from edge-on), some light falls on it with `N·L` times its
/// diffuse level above 0.015 (at least 4/255 of a diffuse 1), in every named view. (A single triangle facing away from the three fixed
/// lights was drawn at the background's colour.)
#[test]
fn every_face_the_camera_sees_is_lit() {
    let d = dir("rig");
    let path = write(
        &d,
        "tri.obj",
        b"v 1.080975 0.465248 0.784243\nv -0.896898 0.761929 0.784243\nv -0.138058 -0.920383 -1.176365\nf 1 2 3\n",
    );
    let views = [
        None,
        Some(ViewName::Front),
        Some(ViewName::Top),
        Some(ViewName::Left),
        Some(ViewName::Iso),
    ];
    for view in views {
        let scene = load_with(
            &path,
            &ModelOptions {
                view,
                ..ModelOptions::default()
            },
        )
        .unwrap()
        .scene;
        let v = (scene.camera.eye() - scene.camera.target()).normalize();
        // Each light's direction to it, scaled by its diffuse grey level.
        let to_lights: Vec<Vec3> = scene
            .lighting
            .lights()
            .iter()
            .filter_map(|l| Some(l.to_light()? * l.color().diffuse().to_array()[1]))
            .collect();
        assert_eq!(to_lights.len(), scene.lighting.lights().len(), "directional lights");
        // Normals on a fine grid of the sphere (azimuth × height).
        let mut worst = f32::INFINITY;
        for i in 0..180 {
            for j in 1..90 {
                let (a, z) = (i as f32 * 2.0f32.to_radians(), -1.0 + j as f32 / 45.0);
                let r = (1.0 - z * z).sqrt();
                let n = Vec3::new(r * a.cos(), r * a.sin(), z);
                if n.dot(v) > 0.0872 {
                    let best = to_lights.iter().map(|l| n.dot(*l)).fold(f32::MIN, f32::max);
                    worst = worst.min(best);
                }
            }
        }
        assert!(
            worst > 0.015,
            "{view:?}: a visible face gets N·L·level = {worst} at most"
        );
    }
}

/// `phong render MODEL` computes a large model's normals beside its framing, on a second
/// thread (the model's `drawn` meshes); `scene_of_model` (batch, Python) computes them in the
/// scene reader. Both give the same scene, bit for bit: camera, sides, and each object's
/// positions, normals and triangles. Models of 20k triangles and more without normals: a
/// smooth torus and a teapot with rims and a spout (creases, split vertices), as OBJ and as
/// binary STL; and as glTF, drawn flat (one normal a triangle), which neither way computes
/// beside the framing (the scene reader places it on both), read alike either way. Where the
/// normals are not computed beside (the glTFs, a small OBJ of two parts), `phong render MODEL`
/// hands the framing's fitted vertices to the scene reader, which computes them otherwise.
#[test]
fn normals_beside_the_framing_are_the_scene_readers() {
    let d = dir("beside");
    let obj = |m: &phong_core::Mesh| {
        let mut s = String::new();
        for p in m.positions() {
            s += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        for t in m.triangles() {
            s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        s.into_bytes()
    };
    let stl = |m: &phong_core::Mesh| {
        let mut b = vec![0u8; 80];
        b.extend((m.triangles().len() as u32).to_le_bytes());
        for t in m.triangles() {
            b.extend([0u8; 12]);
            for &i in t {
                for c in m.positions()[i as usize].to_array() {
                    b.extend(c.to_le_bytes());
                }
            }
            b.extend([0u8; 2]);
        }
        b
    };
    // A glTF of positions and triangles alone (drawn flat).
    let gltf = |m: &phong_core::Mesh| {
        let mut bin: Vec<u8> = bytemuck::cast_slice(m.positions()).to_vec();
        bin.extend_from_slice(bytemuck::cast_slice(m.triangles()));
        let (np, nt) = (m.positions().len(), m.triangles().len());
        let (lo, hi) = m.bounds().unwrap();
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        format!(
            r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {pl}}}, {{"buffer": 0, "byteOffset": {pl}, "byteLength": {tl}}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": {np}, "type": "VEC3", "min": {lo:?}, "max": {hi:?}}},
    {{"bufferView": 1, "componentType": 5125, "count": {ni}, "type": "SCALAR"}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
            len = bin.len(),
            pl = 12 * np,
            tl = 12 * nt,
            ni = 3 * nt,
            lo = lo.to_array(),
            hi = hi.to_array(),
        )
        .into_bytes()
    };
    let torus = phong_core::primitives::torus(160, 1.0, 0.35);
    let teapot = phong_core::primitives::teapot(20);
    let mut files = Vec::new();
    for (name, mesh) in [("torus", &torus), ("teapot", &teapot)] {
        assert!(mesh.triangles().len() >= 20_000, "{name}: {}", mesh.triangles().len());
        files.push(write(&d, &format!("{name}.obj"), &obj(mesh)));
        files.push(write(&d, &format!("{name}.stl"), &stl(mesh)));
        files.push(write(&d, &format!("{name}.gltf"), &gltf(mesh)));
    }
    // Two parts below that size (not beside the framing), moved apart: each takes its share of
    // the framing's fitted vertices.
    let (one, two) = (
        phong_core::primitives::torus(12, 1.0, 0.3),
        phong_core::primitives::torus(16, 1.0, 0.3),
    );
    let mut parts = String::new();
    for (k, (name, m)) in [("one", &one), ("two", &two)].into_iter().enumerate() {
        let base = if k == 0 { 0 } else { one.positions().len() };
        parts += &format!("g {name}\n");
        for p in m.positions() {
            parts += &format!("v {} {} {}\n", p.x + 3.0 * k as f32, p.y, p.z);
        }
        for t in m.triangles() {
            parts += &format!(
                "f {} {} {}\n",
                t[0] as usize + base + 1,
                t[1] as usize + base + 1,
                t[2] as usize + base + 1
            );
        }
    }
    files.push(write(&d, "parts.obj", parts.as_bytes()));
    let bits = |v: &[Vec3]| v.iter().map(|x| x.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    // Each corner's normal in turn (a flat mesh's are its triangles').
    let corner_normals = |m: &phong_core::Mesh| -> Vec<Vec3> {
        (0..m.triangles().len())
            .flat_map(|t| (0..3).map(move |k| m.corner_normal(t, k)))
            .collect()
    };
    for path in &files {
        let options = ModelOptions::default();
        let beside = load_with(path, &options).unwrap();
        let model = ModelFile::read(path).unwrap();
        let reader = phong_scene::scene_of_model(path, &model, &options).unwrap();
        let (a, b) = (&beside.scene, &reader.scene);
        // (Compared as `==`, not by `assert_eq!`: a difference would print every vertex.)
        let same = |equal: bool, what: &str| assert!(equal, "{}: {what} differ", path.display());
        same(format!("{:?}", a.camera) == format!("{:?}", b.camera), "cameras");
        same(format!("{:?}", a.lighting) == format!("{:?}", b.lighting), "lights");
        same(a.objects.len() == b.objects.len(), "object counts");
        for (x, y) in a.objects.iter().zip(&b.objects) {
            same(bits(x.mesh.positions()) == bits(y.mesh.positions()), "positions");
            let (nx, ny) = (corner_normals(&x.mesh), corner_normals(&y.mesh));
            same(bits(x.mesh.normals()) == bits(y.mesh.normals()), "normals");
            same(bits(&nx) == bits(&ny), "corner normals");
            same(
                x.mesh.face_normals().is_some() == y.mesh.face_normals().is_some(),
                "forms",
            );
            same(x.mesh.triangles() == y.mesh.triangles(), "triangles");
            same(
                format!("{:?}", x.shading) == format!("{:?}", y.shading),
                "shading settings",
            );
            let unit = nx.iter().filter(|n| (n.length() - 1.0).abs() < 1e-4).count();
            assert!(
                !nx.is_empty() && unit * 100 >= nx.len() * 99,
                "{}: normals computed",
                path.display()
            );
            // A glTF without normals is flat: one normal a triangle, the vertices shared.
            let gltf = path.extension().is_some_and(|e| e == "gltf");
            same(x.mesh.face_normals().is_some() == gltf, "flat form");
        }
    }
}

/// Quantized attributes (KHR_mesh_quantization, as gltfpack and glTF-Transform write them; and
/// the core's normalized texture coordinates and colours): every component type an attribute
/// may have is read as the specification maps it, through strided views. A triangle with
/// positions in normalized shorts (moved and scaled by its node), normals and tangents in
/// normalized signed bytes, texture coordinates in normalized signed bytes (which the `gltf`
/// crate's reader met with a panic) and in plain unsigned shorts, colours in normalized
/// unsigned shorts: the values below are the specification's formulas worked by hand. A
/// component type the specification does not allow for an attribute is an error naming it.
#[test]
fn gltf_quantized_attributes_are_read() {
    let d = dir("gltf_quantized");
    solid_png(&d, "t.png", [200, 100, 50]);
    let mut bin: Vec<u8> = Vec::new();
    // Positions (i16, a stride of 8), normals (i8, stride 4), TEXCOORD_0 (i8, stride 4),
    // TEXCOORD_1 (u16), COLOR_0 (u16 RGBA), TANGENT (i8 RGBA).
    for p in [[0i16, 0, 0], [16384, 0, 0], [0, 32767, -32767]] {
        p.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
        bin.extend_from_slice(&[0, 0]);
    }
    for _ in 0..3 {
        bin.extend_from_slice(&[0, 0, 127, 0]);
    }
    for uv in [[0i8, 0], [127, 0], [0, -127]] {
        bin.extend_from_slice(&[uv[0] as u8, uv[1] as u8, 0, 0]);
    }
    for uv in [[0u16, 0], [2, 0], [0, 3]] {
        uv.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    for _ in 0..3 {
        [65535u16, 32768, 0, 65535]
            .iter()
            .for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    for _ in 0..3 {
        bin.extend_from_slice(&[127, 0, 0, (-127i8) as u8]);
    }
    assert_eq!(bin.len(), 96);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    // `types`: the component types of NORMAL, TEXCOORD_0 and COLOR_0 (with "normalized").
    let gltf = |types: [&str; 3]| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["KHR_mesh_quantization"],
  "extensionsRequired": ["KHR_mesh_quantization"],
  "buffers": [{{"byteLength": 96, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 24, "byteStride": 8}},
                  {{"buffer": 0, "byteOffset": 24, "byteLength": 12, "byteStride": 4}},
                  {{"buffer": 0, "byteOffset": 36, "byteLength": 12, "byteStride": 4}},
                  {{"buffer": 0, "byteOffset": 48, "byteLength": 12}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": 24}},
                  {{"buffer": 0, "byteOffset": 84, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC3", "min": [0,0,-32767], "max": [16384,32767,0]}},
    {{"bufferView": 1, {n}, "count": 3, "type": "VEC3"}},
    {{"bufferView": 2, {t}, "count": 3, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5123, "count": 3, "type": "VEC2"}},
    {{"bufferView": 4, {c}, "count": 3, "type": "VEC4"}},
    {{"bufferView": 5, "componentType": 5120, "normalized": true, "count": 3, "type": "VEC4"}}],
  "images": [{{"uri": "t.png"}}], "textures": [{{"source": 0}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}, "normalTexture": {{"index": 0}},
                  "occlusionTexture": {{"index": 0, "texCoord": 1}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TEXCOORD_1": 3,
                                                "COLOR_0": 4, "TANGENT": 5}}, "material": 0}}]}}],
  "nodes": [{{"mesh": 0, "translation": [1, 0, 0], "scale": [2, 2, 2]}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
            n = types[0],
            t = types[1],
            c = types[2],
        )
    };
    let (i8n, u16n) = (
        r#""componentType": 5120, "normalized": true"#,
        r#""componentType": 5123, "normalized": true"#,
    );
    let p = write(&d, "q.gltf", gltf([i8n, i8n, u16n]).as_bytes());
    let mut w = Vec::new();
    let parts = load_model(&p, &mut w).unwrap();
    let mesh = &parts[0].mesh;
    // Position: node · (c / 32767) = 1 + 2 c / 32767 in x, 2 c / 32767 in y and z.
    let q = |c: f64| 2.0 * c / 32767.0;
    let want = [[1.0, 0.0, 0.0], [1.0 + q(16384.0), 0.0, 0.0], [1.0, 2.0, -2.0]];
    for (got, want) in mesh.positions().iter().zip(want) {
        assert!(
            (got.as_dvec3() - DVec3::from_array(want)).abs().max_element() < 1e-6,
            "{got} vs {want:?}"
        );
    }
    assert_eq!(mesh.normals(), &[Vec3::Z; 3][..], "127 / 127 = 1");
    // Normalized signed bytes: c / 127, v flipped to OpenGL's (1 − v).
    assert_eq!(
        mesh.uvs(),
        &[Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 2.0)][..]
    );
    // Plain shorts: their values.
    assert_eq!(
        mesh.uvs1(),
        &[Vec2::new(0.0, 1.0), Vec2::new(2.0, 1.0), Vec2::new(0.0, -2.0)][..]
    );
    for c in mesh.colors() {
        let want = [1.0, 32768.0 / 65535.0, 0.0];
        assert!(
            c.to_array().iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-7),
            "{c:?}"
        );
    }
    assert_eq!(mesh.tangents(), &[glam::Vec4::new(1.0, 0.0, 0.0, -1.0); 3][..]);
    assert!(w.is_empty(), "{w:?}");
    // Unsigned colours without the `normalized` flag (which the specification asks for) are
    // read as normalized all the same, as before.
    let p = write(&d, "q2.gltf", gltf([i8n, i8n, r#""componentType": 5123"#]).as_bytes());
    let parts2 = load_model(&p, &mut Vec::new()).unwrap();
    assert_eq!(parts2[0].mesh.colors(), mesh.colors());
    // Types the specification does not allow: unsigned normals, 32-bit texture coordinates,
    // signed colours.
    for (types, name) in [
        ([r#""componentType": 5121, "normalized": true"#, i8n, u16n], "NORMAL"),
        ([i8n, r#""componentType": 5125"#, u16n], "TEXCOORD_0"),
        ([i8n, i8n, i8n], "COLOR_0"),
    ] {
        let p = write(&d, "bad.gltf", gltf(types).as_bytes());
        let e = load_model(&p, &mut Vec::new()).unwrap_err().to_string();
        assert!(
            e.contains("bad.gltf") && e.contains(name) && e.contains("component type"),
            "{e}"
        );
    }
}

/// EXT_texture_webp (glTF-Transform's and gltfpack's WebP textures): a texture whose only
/// image is the extension's WebP is read, required or not, its texels those of the lossless
/// WebP written here; where a texture gives both, its core image (the fallback) is read; a
/// texture with neither is not used, with a warning naming it.
#[test]
fn gltf_webp_textures_are_read() {
    let d = dir("gltf_webp");
    let webp = image::RgbaImage::from_fn(2, 2, |x, y| image::Rgba([255 * x as u8, 255 * y as u8, 0, 255]));
    let mut bytes = Vec::new();
    image::codecs::webp::WebPEncoder::new_lossless(&mut bytes)
        .encode(webp.as_raw(), 2, 2, image::ExtendedColorType::Rgba8)
        .unwrap();
    write(&d, "t.webp", &bytes);
    solid_png(&d, "t.png", [0, 0, 255]);
    let b64 = triangle_with_uvs(&[]);
    let gltf = |texture: &str| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["EXT_texture_webp"], "extensionsRequired": ["EXT_texture_webp"],
  "buffers": [{{"byteLength": 60, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 24}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}],
  "images": [{{"uri": "t.png"}}, {{"uri": "t.webp", "mimeType": "image/webp"}}],
  "textures": [{texture}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "material": 0}}]}}],
  "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#
        )
    };
    let texels = |texture: &str| {
        let p = write(&d, "w.gltf", gltf(texture).as_bytes());
        let mut w = Vec::new();
        let parts = load_model(&p, &mut w).unwrap();
        let map = parts[0].maps.diffuse.as_ref().map(|m| {
            let t = &m.texture;
            [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(x, y)| t.texel(0, x, y))
        });
        (map, w)
    };
    // The WebP's corners: red grows with x, green with the image's y, which runs down (texel
    // rows run up, OpenGL's way: texel row 0 is the image's last; sRGB 255 and 0 are 1 and 0).
    let (webp_texels, w) = texels(r#"{"extensions": {"EXT_texture_webp": {"source": 1}}}"#);
    assert!(w.is_empty(), "{w:?}");
    let want = [
        [0.0, 1.0, 0.0, 1.0],
        [1.0, 1.0, 0.0, 1.0],
        [0.0, 0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0, 1.0],
    ];
    assert_eq!(webp_texels, Some(want));
    let (fallback, _) = texels(r#"{"source": 0, "extensions": {"EXT_texture_webp": {"source": 1}}}"#);
    assert_eq!(fallback, Some([[0.0, 0.0, 1.0, 1.0]; 4]), "the core image, blue");
    let (none, w) = texels("{}");
    assert_eq!(none, None);
    assert!(
        w.len() == 1 && w[0].contains("w.gltf") && w[0].contains("texture 0 has no image"),
        "{w:?}"
    );
}

/// KHR_materials_unlit (photogrammetry scans and baked models): the base colour as it is,
/// whatever the lights, so the material is all emission (its factor, its alpha) with no
/// ambient, diffuse or specular term, and the base colour texture is its emission map; the
/// other textures do not apply, and vertex colours (a tint of the diffuse) are left out with
/// a warning. Required or only used, it is read alike.
#[test]
fn gltf_unlit_materials_are_emission() {
    let d = dir("gltf_unlit");
    solid_png(&d, "t.png", [255, 0, 0]);
    // Three RGBA8 colours after the triangle's positions and texture coordinates.
    let b64 = triangle_with_uvs(&[255, 255, 0, 255].repeat(3));
    let gltf = |required: &str, unlit: &str| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["KHR_materials_unlit"], {required}
  "buffers": [{{"byteLength": 72, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 24}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"}}],
  "images": [{{"uri": "t.png"}}], "textures": [{{"source": 0}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.2, 0.4, 0.6, 0.5], "metallicFactor": 0,
                                           "baseColorTexture": {{"index": 0}}}},
                  "normalTexture": {{"index": 0}}, "emissiveFactor": [1, 1, 1]{unlit}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 2}}, "material": 0}}]}}],
  "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#
        )
    };
    let unlit = r#", "extensions": {"KHR_materials_unlit": {}}"#;
    for required in ["", r#""extensionsRequired": ["KHR_materials_unlit"],"#] {
        let p = write(&d, "u.gltf", gltf(required, unlit).as_bytes());
        let mut w = Vec::new();
        let parts = load_model(&p, &mut w).unwrap();
        let (m, maps) = (parts[0].material.unwrap(), &parts[0].maps);
        let black = phong_core::Color::BLACK;
        assert_eq!((m.ambient(), m.diffuse(), m.specular()), (black, black, black));
        assert_eq!((m.emission(), m.alpha()), (phong_core::Color::new(0.2, 0.4, 0.6), 0.5));
        let emission = maps
            .emission
            .as_ref()
            .expect("the base colour texture as the emission map");
        assert_eq!(emission.texture.texel(0, 0, 0), [1.0, 0.0, 0.0, 1.0]);
        assert!(maps.diffuse.is_none() && maps.normal.is_none());
        assert!(parts[0].mesh.colors().is_empty());
        assert!(
            w.len() == 1 && w[0].contains("u.gltf") && w[0].contains("COLOR_0") && w[0].contains("unlit"),
            "{w:?}"
        );
    }
    assert!(parts_alpha(&gltf("", unlit), &d).is_none(), "opaque: no alpha map");
    // Cut out: the base colour texture's alpha is the alpha map, tested at the cutoff.
    let mask = r#", "alphaMode": "MASK", "alphaCutoff": 0.25, "extensions": {"KHR_materials_unlit": {}}"#;
    let (channel, cutoff) = parts_alpha(&gltf("", mask), &d).expect("an alpha map");
    assert_eq!((channel, cutoff), (phong_core::Channel::A, Some(0.25)));
    // Cut out, its texture without an image: neither map, and one warning for the texture
    // (it would have been both).
    let imageless = gltf("", mask).replace(r#""textures": [{"source": 0}]"#, r#""textures": [{}]"#);
    let p = write(&d, "n.gltf", imageless.as_bytes());
    let mut w = Vec::new();
    let parts = load_model(&p, &mut w).unwrap();
    assert!(parts[0].maps.emission.is_none() && parts[0].maps.alpha.is_none());
    let no_image: Vec<_> = w.iter().filter(|w| w.contains("texture 0 has no image")).collect();
    assert_eq!(no_image.len(), 1, "{w:?}");
    // The same material lit: the base colour is its diffuse, the texture its diffuse map.
    let p = write(&d, "l.gltf", gltf("", "").as_bytes());
    let parts = load_model(&p, &mut Vec::new()).unwrap();
    assert_eq!(
        parts[0].material.unwrap().diffuse(),
        phong_core::Color::new(0.2, 0.4, 0.6)
    );
    assert!(parts[0].maps.diffuse.is_some());
}

/// A 2×2 PNG of one colour, `name` in `d`.
fn solid_png(d: &Path, name: &str, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(2, 2, image::Rgb(rgb))
        .save(d.join(name))
        .unwrap();
}

/// The buffer of a glTF triangle, base64: positions (0, 0, 0), (1, 0, 0), (0, 1, 0) in bytes
/// 0–35, texture coordinates (0, 0), (1, 0), (0, 1) in bytes 36–59, then `extra`.
fn triangle_with_uvs(extra: &[u8]) -> String {
    let mut bin = Vec::new();
    for x in [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0,
    ] {
        bin.extend_from_slice(&x.to_le_bytes());
    }
    bin.extend_from_slice(extra);
    base64::engine::general_purpose::STANDARD.encode(&bin)
}

/// The alpha map's channel and the alpha test's cutoff of the first part of the glTF `json`
/// (written in `d`), if it has an alpha map.
fn parts_alpha(json: &str, d: &Path) -> Option<(phong_core::Channel, Option<f32>)> {
    let p = write(d, "a.gltf", json.as_bytes());
    let parts = load_model(&p, &mut Vec::new()).unwrap();
    let maps = &parts[0].maps;
    maps.alpha.as_ref().map(|(_, c)| (*c, maps.alpha_cutoff))
}
