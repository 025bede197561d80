//! PLY and STL models, and how a model's format is told: files written here byte by byte, so
//! that what they hold is known independently of the readers.

use glam::Vec3;
use phong_scene::{Error, ModelFile, ModelFormat, load};

/// The parts of the model at `path`, its warnings added to `warnings`.
fn load_model(path: &std::path::Path, warnings: &mut Vec<String>) -> Result<Vec<phong_scene::ModelPart>, Error> {
    let model = ModelFile::read(path)?;
    warnings.extend(model.warnings);
    Ok(model.parts)
}

use std::path::{Path, PathBuf};

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("phong-formats-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(d: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = d.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The unit cube's 8 corners and its 6 faces as quads, counter-clockwise from outside.
const CUBE_V: [[f32; 3]; 8] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [0.0, 1.0, 1.0],
];
const CUBE_F: [[u32; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

fn ascii_ply_cube() -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\ncomment a cube\nelement vertex 8\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 6\n\
         property list uchar int vertex_indices\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n\
         end_header\n",
    );
    for v in CUBE_V {
        s += &format!("{} {} {} 255 0 0\n", v[0], v[1], v[2]);
    }
    for f in CUBE_F {
        s += &format!("4 {} {} {} {}\n", f[0], f[1], f[2], f[3]);
    }
    s += "0 1\n";
    s
}

/// A binary PLY's `format` for the byte order.
fn ply_order(big: bool) -> &'static str {
    if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    }
}

/// A binary PLY of the cube with normals, in either byte order.
fn binary_ply_cube(big: bool) -> Vec<u8> {
    let order = ply_order(big);
    let mut b = format!(
        "ply\nformat {order} 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nelement face 6\n\
         property list uchar uint vertex_index\nend_header\n"
    )
    .into_bytes();
    let f32b = |x: f32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    let u32b = |x: u32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
    for v in CUBE_V {
        let n = (Vec3::from_array(v) - 0.5).normalize();
        for c in v.into_iter().chain(n.to_array()) {
            b.extend(f32b(c));
        }
    }
    for f in CUBE_F {
        b.push(4);
        for i in f {
            b.extend(u32b(i));
        }
    }
    b
}

/// A binary STL of `tris`, its header beginning with "solid" as some exporters write it.
fn binary_stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = b"solid exported by a tool that writes binary STL".to_vec();
    b.resize(80, b' ');
    b.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        for c in [0.0f32; 3].into_iter().chain(t.iter().flatten().copied()) {
            b.extend(c.to_le_bytes());
        }
        b.extend([0u8; 2]);
    }
    b
}

fn cube_triangles() -> Vec<[[f32; 3]; 3]> {
    CUBE_F
        .iter()
        .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
        .map(|t| t.map(|i| CUBE_V[i as usize]))
        .collect()
}

/// Each of the mesh's triangles as its three corners.
fn corners(m: &phong_core::Mesh) -> Vec<[[f32; 3]; 3]> {
    m.triangles()
        .iter()
        .map(|t| t.map(|i| m.positions()[i as usize].to_array()))
        .collect()
}

#[test]
fn ply_ascii_and_binary_in_both_byte_orders() {
    let d = dir("ply");
    let want = cube_triangles();
    for (name, bytes) in [
        ("ascii.ply", ascii_ply_cube().into_bytes()),
        ("little.ply", binary_ply_cube(false)),
        ("big.ply", binary_ply_cube(true)),
    ] {
        let p = write(&d, name, &bytes);
        assert_eq!(ModelFormat::detect(&p, &bytes).unwrap(), ModelFormat::Ply);
        let parts = load_model(&p, &mut Vec::new()).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(parts.len(), 1);
        let m = &parts[0].mesh;
        // Quads as two triangles each, the same corners in the same order as written.
        assert_eq!(corners(m), want, "{name}");
        assert_eq!(parts[0].has_normals, name != "ascii.ply", "{name}");
        if parts[0].has_normals {
            for (p, n) in m.positions().iter().zip(m.normals()) {
                assert!((*n - (*p - 0.5).normalize()).length() < 1e-6, "{name}: {p} {n}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(d);
}

/// Triangle faces of `uchar` counts and 32-bit indices (the layout most writers use) in both
/// byte orders, signed and unsigned, with a quad among them: the corners are the ones written,
/// in order (the cube's faces, the quads cut as the general reader cuts them); a negative index
/// is refused with its value, and a file that ends inside a face names the face element.
#[test]
fn ply_triangles_of_int_indices() {
    let d = dir("ply-tris");
    // The cube's faces as triangles, but its fourth face left a quad.
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for (k, f) in CUBE_F.iter().enumerate() {
        if k == 3 {
            faces.push(f.to_vec());
        } else {
            faces.push(vec![f[0], f[1], f[2]]);
            faces.push(vec![f[0], f[2], f[3]]);
        }
    }
    let file = |big: bool, index: &str, faces: &[Vec<u32>], negative: bool| {
        let order = ply_order(big);
        let mut b = format!(
            "ply\nformat {order} 1.0\nelement vertex 8\nproperty float x\nproperty float y\n\
             property float z\nelement face {}\nproperty list uchar {index} vertex_indices\nend_header\n",
            faces.len()
        )
        .into_bytes();
        for v in CUBE_V {
            for c in v {
                b.extend(if big { c.to_be_bytes() } else { c.to_le_bytes() });
            }
        }
        for (k, f) in faces.iter().enumerate() {
            b.push(f.len() as u8);
            for &i in f {
                let i = if negative && k == 5 { u32::MAX } else { i };
                b.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
            }
        }
        b
    };
    let want = cube_triangles();
    for big in [false, true] {
        for index in ["int", "uint", "int32"] {
            let name = format!("{big}-{index}.ply");
            let p = write(&d, &name, &file(big, index, &faces, false));
            let parts = load_model(&p, &mut Vec::new()).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(corners(&parts[0].mesh), want, "{name}");
            // Index 2^32 − 1 in face 5: −1 as a signed int, past the vertices unsigned.
            let p = write(&d, &name, &file(big, index, &faces, true));
            let err = load_model(&p, &mut Vec::new()).unwrap_err().to_string();
            let bad = if index == "uint" { "4294967295" } else { "-1" };
            assert!(
                err.contains(&format!("face 5: vertex index {bad} is out of range")),
                "{name}: {err}"
            );
            // Cut inside face row 8 (after the quad).
            let whole = file(big, index, &faces, false);
            let p = write(&d, &name, &whole[..whole.len() - 2 * 13 - 6]);
            let err = load_model(&p, &mut Vec::new()).unwrap_err().to_string();
            assert!(err.contains("element face row 8"), "{name}: {err}");
        }
    }
    let _ = std::fs::remove_dir_all(d);
}

/// The common binary layout read without the general reader's dispatch: float x, y, z alone
/// (the bytes copied whole where little-endian) or among other scalar properties (a `uchar`
/// between y and z, a `double` after), faces all triangles. In both byte orders and both index
/// types, the corners are the ones written; a negative
/// index, an index past the vertices, a position not finite, bytes after the faces and a file
/// that ends early are read or refused as the general reader reads or refuses them.
#[test]
fn ply_plain_binary_triangles() {
    let d = dir("ply-plain");
    let want = cube_triangles();
    let faces: Vec<[u32; 3]> = CUBE_F
        .iter()
        .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
        .collect();
    let file = |(big, extras): (bool, bool), index: &str, bad: Option<(usize, u32)>, nan: bool| {
        let order = ply_order(big);
        let (flags, quality) = if extras {
            ("property uchar flags\n", "property double quality\n")
        } else {
            ("", "")
        };
        let mut b = format!(
            "ply\nformat {order} 1.0\nelement vertex 8\nproperty float x\nproperty float y\n\
             {flags}property float z\n{quality}element face {}\n\
             property list uchar {index} vertex_indices\nend_header\n",
            faces.len()
        )
        .into_bytes();
        for (k, v) in CUBE_V.iter().enumerate() {
            let v = if nan && k == 2 { [v[0], f32::NAN, v[2]] } else { *v };
            let f = |x: f32| if big { x.to_be_bytes() } else { x.to_le_bytes() };
            b.extend(f(v[0]));
            b.extend(f(v[1]));
            if extras {
                b.push(7);
            }
            b.extend(f(v[2]));
            if extras {
                b.extend(if big {
                    0.5f64.to_be_bytes()
                } else {
                    0.5f64.to_le_bytes()
                });
            }
        }
        for (k, f) in faces.iter().enumerate() {
            b.push(3);
            for (c, &i) in f.iter().enumerate() {
                let i = match bad {
                    Some((face, value)) if face == k && c == 1 => value,
                    _ => i,
                };
                b.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
            }
        }
        b
    };
    let read = |name: &str, bytes: &[u8]| {
        let p = write(&d, name, bytes);
        load_model(&p, &mut Vec::new()).map(|parts| corners(&parts[0].mesh))
    };
    for big in [false, true] {
        for (extras, index) in [(true, "int"), (true, "uint"), (false, "int"), (false, "uint")] {
            let big = (big, extras);
            let name = format!("{big:?}-{index}.ply");
            assert_eq!(read(&name, &file(big, index, None, false)).unwrap(), want, "{name}");
            let mut longer = file(big, index, None, false);
            longer.extend(b"\n\n");
            assert_eq!(read(&name, &longer).unwrap(), want, "{name} with bytes after");
            let err = read(&name, &file(big, index, Some((4, u32::MAX)), false))
                .unwrap_err()
                .to_string();
            let shown = if index == "uint" { "4294967295" } else { "-1" };
            assert!(
                err.contains(&format!("face 4: vertex index {shown} is out of range")),
                "{name}: {err}"
            );
            let err = read(&name, &file(big, index, Some((9, 8)), false))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("face 9: vertex index 8 is out of range (8 vertices)"),
                "{name}: {err}"
            );
            let err = read(&name, &file(big, index, None, true)).unwrap_err().to_string();
            assert!(err.contains("vertex 2 is not finite"), "{name}: {err}");
            let whole = file(big, index, None, false);
            let err = read(&name, &whole[..whole.len() - 5]).unwrap_err().to_string();
            assert!(err.contains("element face row 11"), "{name}: {err}");
        }
    }
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn stl_binary_and_ascii() {
    let d = dir("stl");
    let tris = cube_triangles();
    let bin = binary_stl(&tris);
    let mut ascii = String::from("solid cube\n");
    for t in &tris {
        ascii += "facet normal 0 0 0\nouter loop\n";
        for v in t {
            ascii += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
        }
        ascii += "endloop\nendfacet\n";
    }
    ascii += "endsolid cube\n";
    for (name, bytes) in [("bin.stl", bin), ("ascii.stl", ascii.into_bytes())] {
        let p = write(&d, name, &bytes);
        assert_eq!(ModelFormat::detect(&p, &bytes).unwrap(), ModelFormat::Stl, "{name}");
        let parts = load_model(&p, &mut Vec::new()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let m = &parts[0].mesh;
        assert_eq!(corners(m), tris, "{name}");
        // Equal corners share a vertex: the cube's 8.
        assert_eq!(m.positions().len(), 8, "{name}");
    }
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn the_format_is_told_by_content_then_extension() {
    let d = dir("sniff");
    // A PLY named .stl is a PLY; an STL named .dat is an STL and `load` frames it as a model.
    let ply = write(&d, "misnamed.stl", ascii_ply_cube().as_bytes());
    assert_eq!(load_model(&ply, &mut Vec::new()).unwrap()[0].mesh.triangles().len(), 12);
    let stl = write(&d, "cube.dat", &binary_stl(&cube_triangles()));
    let scene = load(&stl).unwrap().scene;
    assert_eq!(scene.triangle_count(), 12);
    // A truncated GLB is a glTF error naming the file; what is none of the formats names the
    // formats.
    let gltf = write(&d, "box.glb", b"glTF\x02\x00\x00\x00");
    let e = load_model(&gltf, &mut Vec::new()).unwrap_err();
    assert!(e.is_input() && e.to_string().contains("box.glb: glTF: "), "{e}");
    let other = write(&d, "points.xyz", b"1 2 3\n4 5 6\n");
    let e = load_model(&other, &mut Vec::new()).unwrap_err().to_string();
    assert!(
        e.contains("points.xyz: not a model phong reads (OBJ .obj, PLY .ply, STL .stl, glTF .gltf/.glb)"),
        "{e}"
    );
    // A mesh in a format phong does not read (ModelNet's OFF) is named as such, not read as a
    // scene file (whose TOML error would be no help).
    let off = write(&d, "chair.OFF", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    assert!(phong_scene::is_model_path(&off));
    let e = load(&off).unwrap_err();
    assert!(e.is_input(), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: not a model phong reads (OBJ .obj, PLY .ply, STL .stl, glTF .gltf/.glb); .off is not one of them",
            off.display()
        )
    );
    let _ = std::fs::remove_dir_all(d);
}

/// The binary cube with a NaN for vertex 0's x.
fn nan_binary() -> Vec<u8> {
    let mut b = binary_ply_cube(false);
    let at = b.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    b[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    b
}

/// Broken files are errors naming the file and the fault, quickly, never a panic or an
/// allocation sized by a header's claim.
#[test]
fn broken_ply_and_stl_are_errors() {
    let d = dir("broken");
    let good = ascii_ply_cube();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "index.ply",
            good.replace("4 0 3 2 1", "4 0 3 2 9").into_bytes(),
            "vertex index 9 is out of range",
        ),
        (
            "huge.ply",
            good.replace("element vertex 8", "element vertex 4000000000")
                .into_bytes(),
            "malformed PLY",
        ),
        ("cut.ply", binary_ply_cube(false)[..300].to_vec(), "malformed PLY"),
        (
            "nan.ply",
            good.replace("1 1 1 255", "nan 1 1 255").into_bytes(),
            "element vertex row 6 (line 23): `nan` is not a finite number",
        ),
        ("nan-binary.ply", nan_binary(), "vertex 0 is not finite"),
        (
            "points.ply",
            good.replace("element face 6", "element face 0").into_bytes(),
            "no faces",
        ),
        (
            "noheader.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\n".to_vec(),
            "malformed PLY",
        ),
        // Found by the ply_stl fuzz target: a count past u64 panicked inside ply-rs, also on a
        // line that merely contains `end_header`.
        (
            "word.ply",
            good.replace(
                "element vertex 8",
                "element vend_headerertex 900000000000000000000000 7",
            )
            .into_bytes(),
            "the number 900000000000000000000000 is too large",
        ),
        (
            "count.ply",
            good.replace("element face 6", "element face 666666666666666666666666")
                .into_bytes(),
            "header line 11: the number 666666666666666666666666 is too large",
        ),
        (
            "cut.stl",
            binary_stl(&cube_triangles())[..200].to_vec(),
            "malformed STL",
        ),
    ];
    for (name, bytes, want) in cases {
        let p = write(&d, name, &bytes);
        let e: Error = load_model(&p, &mut Vec::new()).unwrap_err();
        let msg = e.to_string();
        assert!(
            e.is_input() && msg.contains(name) && msg.contains(want),
            "{name}: {msg}"
        );
    }
    let _ = std::fs::remove_dir_all(d);
}

/// An ASCII STL of `solids` (name, triangles), each `solid NAME` ... `endsolid NAME`.
fn ascii_stl(solids: &[(&str, Vec<[[f32; 3]; 3]>)]) -> String {
    let mut s = String::new();
    for (name, tris) in solids {
        s += &format!("solid {name}\n");
        for t in tris {
            s += "  facet normal 0 0 0\n    outer loop\n";
            for v in t {
                s += &format!("      vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            s += "    endloop\n  endfacet\n";
        }
        s += &format!("endsolid {name}\n");
    }
    s
}

#[test]
fn ascii_stl_without_a_name_and_with_several_solids() {
    let d = dir("stl-ascii");
    let cube = cube_triangles();
    // `solid` alone on its first line (MeshLab, many CAD exporters): ASCII, by its content.
    let p = write(&d, "noname.stl", ascii_stl(&[("", cube.clone())]).as_bytes());
    let parts = load_model(&p, &mut Vec::new()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(parts.len(), 1);
    assert_eq!(corners(&parts[0].mesh), cube);
    // Two bodies: both read, each a part, in place (the second moved by 3 in x).
    let moved: Vec<[[f32; 3]; 3]> = cube.iter().map(|t| t.map(|v| [v[0] + 3.0, v[1], v[2]])).collect();
    let p = write(
        &d,
        "two.stl",
        ascii_stl(&[("body1", cube.clone()), ("body2", moved.clone())]).as_bytes(),
    );
    let parts = load_model(&p, &mut Vec::new()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(parts.len(), 2);
    assert_eq!(corners(&parts[0].mesh), cube);
    assert_eq!(corners(&parts[1].mesh), moved);
    assert!(parts[1].name.ends_with(":body2"), "{}", parts[1].name);
    let scene = load(&p).unwrap().scene;
    assert_eq!(scene.triangle_count(), 2 * cube.len());
    // A binary file whose header begins with "solid" stays binary.
    let mut bin = binary_stl(&cube);
    bin[..5].copy_from_slice(b"solid");
    let p = write(&d, "solidheader.stl", &bin);
    assert_eq!(corners(&load_model(&p, &mut Vec::new()).unwrap()[0].mesh), cube);
    // What is not STL is refused at its line.
    let p = write(
        &d,
        "bad.stl",
        b"solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 zero\n",
    );
    let e = load_model(&p, &mut Vec::new()).unwrap_err().to_string();
    assert!(
        e.contains("bad.stl: malformed STL: line 4: `zero` is not a number"),
        "{e}"
    );
    let p = write(
        &d,
        "short.stl",
        b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid x\n",
    );
    let e = load_model(&p, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("line 7: a facet has 3 vertices, got 2"), "{e}");
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn files_without_faces_say_what_they_are() {
    let d = dir("nofaces");
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    let cases: [(&str, &[u8], &str); 5] = [
        (
            "cloud.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n",
            "no faces: a point cloud of 4 points",
        ),
        (
            "cloud.ply",
            ply.as_bytes(),
            "no faces: a point cloud of 3 points, nothing to render",
        ),
        ("empty.obj", b"", "an empty file"),
        ("empty.stl", b"", "an empty file"),
        ("blank.ply", b"\n  \n", "an empty file"),
    ];
    for (name, bytes, says) in cases {
        let p = write(&d, name, bytes);
        let e = load_model(&p, &mut Vec::new()).expect_err(name).to_string();
        assert!(e.contains(says), "{name}: {e}");
        assert!(!e.contains("malformed"), "{name}: {e}");
    }
    let _ = std::fs::remove_dir_all(d);
}

/// OBJ statements continued on the next line with `\` (Rhino writes them), and `usemtl` with
/// no name (assimp's test files): read, with the same mesh as the statements on one line and
/// the default material after the unnamed `usemtl`, with a warning.
#[test]
fn obj_continuation_lines_and_unnamed_usemtl() {
    let d = dir("obj-variants");
    let one = write(&d, "one.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n");
    let cont = write(
        &d,
        "cont.obj",
        b"v 0 0 \\\n 0\nv 1 0 0\r\nv 0 1 \\\r\n0\nv 1 1 0\nf 1 2 \\\n 4 \\\n 3\n",
    );
    let a = load_model(&one, &mut Vec::new()).expect("one line each");
    let b = load_model(&cont, &mut Vec::new()).expect("continued lines");
    assert_eq!(corners(&a[0].mesh), corners(&b[0].mesh));
    assert_eq!(corners(&b[0].mesh).len(), 2);
    // An error after continued lines keeps its line number.
    let bad = write(&d, "bad.obj", b"v 0 0 \\\n 0\nv 1 0 0\nv 0 x 0\n");
    let e = load_model(&bad, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("bad.obj:4:"), "{e}");
    write(&d, "m.mtl", b"newmtl red\nKd 1 0 0\n");
    let unnamed = write(
        &d,
        "unnamed.obj",
        b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl red\nf 1 2 3\nusemtl\nf 2 4 3\n",
    );
    let mut w = Vec::new();
    let parts = load_model(&unnamed, &mut w).expect("read");
    assert!(
        w.iter().any(|w| w.contains("`usemtl` statements name no material")),
        "{w:?}"
    );
    let red: Vec<_> = parts
        .iter()
        .filter(|p| p.material.is_some_and(|m| m.diffuse().to_array() == [1.0, 0.0, 0.0]))
        .collect();
    assert_eq!(red.len(), 1, "{:?}", parts.iter().map(|p| &p.name).collect::<Vec<_>>());
    assert_eq!(parts.iter().map(|p| p.mesh.triangles().len()).sum::<usize>(), 2);
    // A name that no library defines: a warning naming it, the default material.
    let undefined = write(
        &d,
        "undefined.obj",
        b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl blue\nf 1 2 3\n",
    );
    let mut w = Vec::new();
    let parts = load_model(&undefined, &mut w).expect("read");
    assert!(
        w.iter().any(|w| w.contains("no MTL library defines (\"blue\")")),
        "{w:?}"
    );
    assert!(parts[0].material.is_none());
    let _ = std::fs::remove_dir_all(d);
}

/// PLY's variants as exporters write them: every scalar type and its other names, doubles
/// for positions, 16-bit colours, an element with lists before the vertices, a face element
/// with other properties around its index list, `\r\n` lines, and a list of shorts: all the
/// cube, the same corners in the same order; 16-bit colours over 65535.
#[test]
fn ply_variants_read_alike() {
    let d = dir("ply-variants");
    let want = cube_triangles();
    let mut b = String::from(
        "ply\r\nformat binary_little_endian 1.0\r\nobj_info made by hand\r\nelement material 2\r\n\
         property list uint8 float32 values\r\nelement vertex 8\r\nproperty float64 x\r\nproperty double y\r\n\
         property float64 z\r\nproperty ushort red\r\nproperty uint16 green\r\nproperty ushort blue\r\n\
         property int8 extra\r\nelement face 6\r\nproperty uchar flags\r\nproperty list uchar short vertex_indices\r\n\
         property float quality\r\nend_header\r\n",
    )
    .into_bytes();
    for k in 0..2u8 {
        b.push(k + 1);
        for _ in 0..=k {
            b.extend(1.5f32.to_le_bytes());
        }
    }
    for v in CUBE_V {
        for c in v {
            b.extend(f64::from(c).to_le_bytes());
        }
        for c in [65535u16, 0, 13107] {
            b.extend(c.to_le_bytes());
        }
        b.push(7);
    }
    for f in CUBE_F {
        b.push(0);
        b.push(4);
        for i in f {
            b.extend((i as i16).to_le_bytes());
        }
        b.extend(0.5f32.to_le_bytes());
    }
    let p = write(&d, "variants.ply", &b);
    let parts = load_model(&p, &mut Vec::new()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(corners(&parts[0].mesh), want);
    assert!(!parts[0].has_normals);
    assert!(parts[0].mesh.colors().iter().all(|c| c.to_array() == [1.0, 0.0, 0.2]));
    // Cut inside the faces: an error at the element and row, never a panic.
    let cut = &b[..b.len() - 10];
    let e = load_model(&write(&d, "cut.ply", cut), &mut Vec::new())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("element face row 5") && e.contains("the file ends inside it"),
        "{e}"
    );
    // Counts past what the file holds are refused before anything is allocated, also for an
    // element of no properties (nothing to read, so nothing to loop over).
    let header = |body: &str| format!("ply\nformat ascii 1.0\n{body}end_header\n");
    for (text, says) in [
        (
            header("element vertex 99999999999\nproperty float x\n"),
            "element vertex claims 99999999999 rows",
        ),
        (header("element nothing 18446744073709551615\n"), "no faces"),
        (
            header("element vertex 18446744073709551615\n"),
            "vertex 0 has no x, y and z",
        ),
        (
            header("element vertex 1\nproperty half x\n"),
            "header line 4: unknown type `half`",
        ),
        ("ply\nelement vertex 1\nend_header\n".to_string(), "no `format` line"),
        (
            header("element face 1\nproperty list float int vertex_indices\n"),
            "count must be of an integer type",
        ),
    ] {
        let e = load_model(&write(&d, "bad.ply", text.as_bytes()), &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{text}: {e}");
    }
    let _ = std::fs::remove_dir_all(d);
}
