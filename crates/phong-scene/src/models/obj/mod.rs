//! Wavefront OBJ and MTL import.
//!
//! The OBJ is read by phong in one pass (`read.rs`), every malformed record reported at its
//! file, line and column, its groups given as tobj's single-index meshes; each MTL is checked
//! line by line (colours, `Ns`, `d`, `illum`) and parsed by tobj.
//!
//! MTL mapping: `Ka`, `Kd`, `Ks`, `Ke` → ambient, diffuse, specular,
//! emission; `Ns` → shininess (the exponent itself, 0..1000); `d` → alpha;
//! `illum` 0 → a constant colour `Kd` (as emission, nothing lit), 1 →
//! Lambert (no specular), 2 → Blinn-Phong; other models are rendered as 2
//! with a warning. Missing `Ka`/`Kd`/`Ks` take OpenGL's default material's values.
//! Texture maps (`map_Kd`, `map_Ka`, `map_Ks`, `map_Ke`, `map_Ns`, `map_d`) with their `-o`,
//! `-s`, `-clamp` and `-imfchan` options: see `texture_file.rs`.

//!
//! The OBJ reader is `read.rs` (with `text.rs`), the MTL libraries `mtl.rs`.

mod mtl;
mod read;
mod text;

use super::ModelPart;
use crate::Error;
use crate::texture_file::{MapRequest, ReadFile, Source, TextureCache, prefetch, resolve};
use glam::{Vec2, Vec3};
use mtl::{check_mtl, mtl_names, normalize_mtl, to_material, transparency};
use phong_core::{Color, Maps, Material, Mesh};
use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use text::lines;

/// The triangles of a tobj mesh's faces (`arities` empty when all are triangles), each
/// polygon triangulated by [`polygon::triangulate`](crate::models::polygon::triangulate).
fn polygons_to_triangles(positions: &[Vec3], indices: &[u32], arities: &[u32]) -> Vec<[u32; 3]> {
    if arities.is_empty() {
        return indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    }
    let mut tris = Vec::with_capacity(indices.len());
    let mut at = 0usize;
    let mut corners = Vec::new();
    for &n in arities {
        let face = &indices[at..at + n as usize];
        at += n as usize;
        if n == 3 {
            tris.push([face[0], face[1], face[2]]);
            continue;
        }
        corners.clear();
        corners.extend(face.iter().map(|&i| positions[i as usize]));
        tris.extend(
            crate::models::polygon::triangulate(&corners)
                .into_iter()
                .map(|t| t.map(|k| face[k as usize])),
        );
    }
    tris
}

/// A model's or material library's text: UTF-8 (a byte-order mark dropped) or, where it is not,
/// Latin-1 (every byte a character, as the files of older tools are), with a warning.
pub(crate) fn decode_text(path: &Path, mut bytes: Vec<u8>, warnings: &mut Vec<String>) -> String {
    if bytes.starts_with(&[0xef, 0xbb, 0xbf]) {
        bytes.drain(..3);
    }
    match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => {
            let bytes = e.into_bytes();
            let at = std::str::from_utf8(&bytes).map_or_else(|e| e.valid_up_to(), |_| 0);
            let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
            warnings.push(format!(
                "{}: not UTF-8 (line {line}, byte 0x{:02x}): read as Latin-1",
                path.display(),
                bytes[at]
            ));
            bytes.iter().map(|&b| char::from(b)).collect()
        }
    }
}

/// A warning for each material that a `usemtl` names and no library defines (its faces take
/// the default material), unless a library was missing (its own warning says so).
fn undefined_materials(path: &Path, used: &[String], defined: &[tobj::Material], warnings: &mut Vec<String>) {
    if warnings.iter().any(|w| w.contains("material library")) {
        return;
    }
    let mut named: Vec<&str> = used
        .iter()
        .filter_map(|l| l.strip_prefix("usemtl "))
        .map(str::trim)
        .filter(|n| !n.is_empty() && *n != text::NO_MATERIAL && !defined.iter().any(|m| m.name == *n))
        .collect();
    named.sort_unstable();
    named.dedup();
    if !named.is_empty() {
        let list = named.iter().map(|n| format!("{n:?}")).collect::<Vec<_>>().join(", ");
        warnings.push(format!(
            "{}: `usemtl` names materials that no MTL library defines ({list}): the default material there",
            path.display()
        ));
    }
}

/// The libraries' materials as phong's, with warnings for what is read otherwise than the
/// file literally says: `Tr` as opacity where every material would vanish by it, `Ns 0` with
/// `Ks` above 0 as no highlight.
fn materials_of(path: &Path, mtl: &[tobj::Material], warnings: &mut Vec<String>) -> Vec<Material> {
    // Every material made wholly invisible by `Tr` alone (`Tr 1`, no `d`): the exporter
    // meant `Tr` as the opacity.
    let vanish = !mtl.is_empty() && mtl.iter().all(|m| transparency(m) == Some(1.0));
    if vanish {
        warnings.push(format!(
            "{}: `Tr 1` with no `d` would make every material of the model invisible (Tr is the \
             transparency, 1 - d): read as the opacity, as some exporters write it (`d 1` says opaque)",
            path.display()
        ));
    }
    let (materials, dimmed): (Vec<Material>, Vec<bool>) = mtl.iter().map(|m| to_material(m, vanish)).unzip();
    let names: Vec<String> = mtl
        .iter()
        .zip(&dimmed)
        .filter(|(_, d)| **d)
        .map(|(m, _)| format!("{:?}", m.name))
        .collect();
    if !names.is_empty() {
        warnings.push(format!(
            "{}: materials {}: `Ns 0` (or no `Ns`) with `Ks` above 0 would light every lit point fully: \
             read as no specular highlight, as Blender reads it",
            path.display(),
            names.join(", ")
        ));
    }
    materials
}

/// An OBJ's text `src` (of `path`) with its MTL libraries read beside it, each added to
/// `sources`.
pub(super) fn obj_from_text(
    path: &Path,
    src: &str,
    warnings: &mut Vec<String>,
    sources: &mut Vec<PathBuf>,
) -> Result<Vec<ModelPart>, Error> {
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let read_mtl = std::cell::RefCell::new(Vec::new());
    let latin1 = std::cell::RefCell::new(Vec::new());
    let moved = std::cell::RefCell::new(Vec::new());
    let out = load_obj_text(
        path,
        src,
        &|mtl| {
            // A name with spaces may be a whole `mtllib` statement tried as one name (see
            // `load_obj_text`): not searched by its last word.
            let name = mtl.to_string_lossy();
            let p = crate::read::found(&dir, &name, !name.contains(char::is_whitespace), path, &moved);
            read_mtl.borrow_mut().push(p.clone());
            let bytes = crate::read_bounded(
                &p,
                phong_core::limits::MAX_MTL_BYTES,
                "material library (MAX_MTL_BYTES)",
            )
            .map_err(|e| match e {
                Error::Read { source, .. } => source,
                other => std::io::Error::other(other.to_string()),
            })?;
            Ok(decode_text(&p, bytes, &mut latin1.borrow_mut()))
        },
        &|name| {
            let found = crate::read::found(&dir, name, true, path, &moved);
            read_mtl.borrow_mut().push(found.clone());
            crate::read_bounded(&found, phong_core::limits::MAX_IMAGE_FILE_BYTES, "texture image").map_err(
                |e| match e {
                    Error::Read { source, .. } => format!("cannot read {}: {source}", found.display()),
                    other => other.to_string(),
                },
            )
        },
        warnings,
    );
    warnings.extend(latin1.into_inner());
    warnings.extend(moved.into_inner());
    sources.extend(read_mtl.into_inner());
    out
}

/// An OBJ's parts from its text `src` (named `path` in messages), its MTL libraries read by
/// `read_mtl` (given the name the `mtllib` line gives) and their texture images by
/// `read_texture` (given the name relative to the OBJ's folder: the MTL's folder joined with
/// the name the statement gives).
pub(super) fn load_obj_text(
    path: &Path,
    src: &str,
    read_mtl: &dyn Fn(&Path) -> std::io::Result<String>,
    read_texture: &ReadFile,
    warnings: &mut Vec<String>,
) -> Result<Vec<ModelPart>, Error> {
    let _budget = crate::texture_file::TextureBudget::start();
    let joined = text::join_continuations(src);
    let src: &str = &joined;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mtl_error: std::cell::RefCell<Option<Error>> = Default::default();
    let mtl_warnings: std::cell::RefCell<Vec<String>> = Default::default();
    let map_requests: std::cell::RefCell<Vec<(String, MapRequest)>> = Default::default();
    let load_mtl = |mtl: &Path| {
        // Located at the `mtllib` statement (its line, not a comment's).
        let name = mtl.to_string_lossy();
        let at = lines(src)
            .filter(|(_, l)| l.split('#').next().unwrap_or("").trim_start().starts_with("mtllib"))
            .find_map(|(start, l)| l.split('#').next().unwrap_or("").find(&*name).map(|i| start + i))
            .unwrap_or(0);
        let mut text = String::new();
        let mut found = false;
        // The statement's text as one name (spaces and all) where it names a library, else
        // each of its names.
        let names = mtl_names(&name);
        let libs = match names.split_first() {
            Some((whole, each)) if !each.is_empty() && read_mtl(whole).is_err() => each,
            _ => &names[..1],
        };
        for lib in libs {
            // The name as written, else its file name beside the OBJ (a path from another
            // machine).
            let mut result = read_mtl(lib);
            let base = lib.file_name().map(PathBuf::from).unwrap_or_default();
            if matches!(&result, Err(e) if e.kind() == std::io::ErrorKind::NotFound) && &base != lib {
                result = read_mtl(&base).map_err(|_| std::io::Error::from(std::io::ErrorKind::NotFound));
            }
            let p: PathBuf = dir.join(lib);
            match result {
                Ok(t) => {
                    let mut requests = Vec::new();
                    if let Err(e) = check_mtl(&p, &t, &mut mtl_warnings.borrow_mut(), &mut requests) {
                        *mtl_error.borrow_mut() = Some(e);
                        return Err(tobj::LoadError::MaterialParseError);
                    }
                    // Texture names are relative to the library's folder; backslashes are
                    // separators.
                    let lib_dir = lib.parent().unwrap_or(Path::new(""));
                    for (_, r) in &mut requests {
                        if let Source::File(f) = &mut r.source {
                            *f = lib_dir.join(f.replace('\\', "/")).to_string_lossy().into_owned();
                        }
                    }
                    map_requests.borrow_mut().extend(requests);
                    text.push_str(&normalize_mtl(&t));
                    text.push('\n');
                    found = true;
                }
                // A library that is not there is a warning, its faces get the default material
                // (as other loaders do); one that is there and cannot be read (a FIFO, too
                // large) is an error.
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    let msg = format!(
                        "material library {} not found: its materials are the default material",
                        p.display()
                    );
                    mtl_warnings
                        .borrow_mut()
                        .push(Error::at(path, src, at, Some("mtllib"), msg).to_string());
                }
                Err(e) => {
                    let msg = format!("material library {} cannot be read: {e}", p.display());
                    *mtl_error.borrow_mut() = Some(Error::at(path, src, at, Some("mtllib"), msg));
                    return Err(tobj::LoadError::OpenFileFailed);
                }
            }
        }
        if !found {
            return Err(tobj::LoadError::OpenFileFailed);
        }
        tobj::load_mtl_buf(&mut BufReader::new(text.as_bytes()))
    };
    let prepared = read::read_obj(path, src, &mut |p| load_mtl(p));
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let prepared = prepared?;
    warnings.extend(prepared.notes.iter().cloned());
    warnings.extend(mtl_warnings.into_inner());
    let (models, materials) = (prepared.models, prepared.materials);
    let tobj_materials: Vec<tobj::Material> = materials.unwrap_or_default();
    undefined_materials(path, &prepared.used, &tobj_materials, warnings);
    let materials = materials_of(path, &tobj_materials, warnings);
    let maps = material_maps(&tobj_materials, map_requests.into_inner(), read_texture, warnings);
    let mut parts = Vec::new();
    for model in models {
        if let Some(part) = part_of(path, src, model, (&materials, &maps), prepared.origin, warnings)? {
            parts.push(part);
        }
    }
    if parts.is_empty() {
        return Err(no_faces(path, src, &prepared.notes));
    }
    Ok(merge_parts(parts))
}

/// Each material's maps, from the requests its MTL statements made, the images read once for
/// the whole file (decoded side by side, then resolved in order).
fn material_maps(
    materials: &[tobj::Material],
    requests: Vec<(String, MapRequest)>,
    read_texture: &ReadFile,
    warnings: &mut Vec<String>,
) -> Vec<Maps> {
    let mut cache = TextureCache::default();
    let mine: Vec<Vec<MapRequest>> = materials
        .iter()
        .map(|m| {
            requests
                .iter()
                .filter(|(name, _)| *name == m.name)
                .map(|(_, r)| r.clone())
                .collect()
        })
        .collect();
    prefetch(&mine, read_texture, &mut cache);
    materials
        .iter()
        .zip(&mine)
        .map(|(m, mine)| resolve(mine, &m.name, read_texture, &mut cache, warnings))
        .collect()
}

/// One group of the file as a part (with its material's index, for merging), or `None` where
/// it has no faces: its polygons triangulated, its normals, texture coordinates and vertex
/// colours where the file gives one a vertex, its material and maps.
fn part_of(
    path: &Path,
    src: &str,
    mut model: tobj::Model,
    (materials, maps): (&[Material], &[Maps]),
    origin: glam::DVec3,
    warnings: &mut Vec<String>,
) -> Result<Option<(ModelPart, Option<usize>)>, Error> {
    let file = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if model.mesh.indices.is_empty() {
        return Ok(None);
    }
    // The flat coordinates taken as points, and the indices as triangles where every face is
    // one, in place where the vectors' sizes allow (the reader sizes them so), else copied.
    let positions: Vec<Vec3> = bytemuck::allocation::try_cast_vec(std::mem::take(&mut model.mesh.positions))
        .unwrap_or_else(|(_, flat)| flat.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect());
    let triangles: Option<Vec<[u32; 3]>> = model.mesh.face_arities.is_empty().then(|| {
        bytemuck::allocation::try_cast_vec(std::mem::take(&mut model.mesh.indices))
            .unwrap_or_else(|(_, flat)| flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
    });
    let m = &model.mesh;
    let has_normals = m.normals.len() == 3 * positions.len();
    let normals = if has_normals {
        m.normals
            .chunks_exact(3)
            .map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or_zero())
            .collect()
    } else {
        vec![Vec3::ZERO; positions.len()]
    };
    let tris = match triangles {
        Some(t) => t,
        None => polygons_to_triangles(&positions, &m.indices, &m.face_arities),
    };
    let n = positions.len();
    // One texture coordinate per vertex where the file gives them (tobj's single index).
    let uvs: Vec<Vec2> = if m.texcoords.len() == 2 * n {
        m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])).collect()
    } else {
        Vec::new()
    };
    // Vertex colours, where the part has no material (they stand for its ambient and
    // diffuse colours, as OpenGL's GL_COLOR_MATERIAL; a material's colours win).
    let material = m.material_id.and_then(|i| materials.get(i).copied());
    let colors: Vec<Color> = if m.vertex_color.len() == 3 * n && material.is_none() {
        m.vertex_color
            .chunks_exact(3)
            .map(|c| Color::new(c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)))
            .collect()
    } else {
        if m.vertex_color.len() == 3 * n {
            warnings.push(format!(
                "{}: group {}: vertex colours not used: the group has a material",
                path.display(),
                model.name
            ));
        }
        Vec::new()
    };
    let coloured = !colors.is_empty();
    let mesh = Mesh::new(positions, normals, tris)
        .and_then(|mesh| mesh.with_uvs(uvs))
        .and_then(|mesh| mesh.with_colors(colors))
        .map_err(|e| Error::at(path, src, 0, None, format!("group {}: {e}", model.name)))?;
    Ok(Some((
        ModelPart {
            name: format!("{file}:{}", model.name),
            mesh,
            material: match material {
                None if coloured => Some(crate::models::vertex_color_material()),
                other => other,
            },
            maps: m
                .material_id
                .and_then(|i| maps.get(i).cloned())
                .map(|mut maps| {
                    // `d` or `Tr` below 1: blended, as the file means it.
                    maps.blend = m
                        .material_id
                        .and_then(|i| materials.get(i))
                        .is_some_and(|m| m.alpha() < 1.0);
                    maps
                })
                .unwrap_or_default(),
            has_normals,
            flat_without_normals: false,
            origin,
            drawn: None,
            fitted: None,
        },
        m.material_id,
    )))
}

/// The error of a file with no faces, saying what it is (points, or nothing) and why records
/// were skipped (`notes`).
fn no_faces(path: &Path, src: &str, notes: &[String]) -> Error {
    Error::at(
        path,
        src,
        0,
        None,
        format!(
            "no faces{} (`f` records with 3 or more vertices): nothing to render{}",
            match src.lines().filter(|l| l.trim_start().starts_with("v ")).count() {
                0 => String::new(),
                n => format!(": a point cloud of {n} points"),
            },
            notes
                .iter()
                .map(|n| {
                    let file = format!("{}: ", path.display());
                    format!("; {}", n.strip_prefix(&file).unwrap_or(n))
                })
                .collect::<String>()
        ),
    )
}

/// Parts that share a material within the same group name, merged (where they agree on
/// having normals).
fn merge_parts(parts: Vec<(ModelPart, Option<usize>)>) -> Vec<ModelPart> {
    let mut merged: Vec<ModelPart> = Vec::new();
    let mut index: HashMap<(String, Option<usize>), usize> = HashMap::new();
    for (p, id) in parts {
        let key = (p.name.clone(), id);
        match index.get(&key) {
            Some(&i) if merged[i].has_normals == p.has_normals => merged[i].mesh.append(&p.mesh),
            _ => {
                index.insert(key, merged.len());
                merged.push(p);
            }
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use phong_core::Color;

    fn load_obj(path: &Path, warnings: &mut Vec<String>) -> Result<Vec<ModelPart>, Error> {
        let model = crate::ModelFile::read(path)?;
        warnings.extend(model.warnings);
        Ok(model.parts)
    }

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    fn tmpdir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("phong-obj-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn quad_with_two_materials() {
        let d = tmpdir("quad");
        write(
            &d,
            "m.mtl",
            "newmtl red\nKa 0.1 0 0\nKd 0.8 0 0\nKs 0.5 0.5 0.5\nNs 20\nillum 2\n\
             newmtl glow\nKd 0 1 0\nillum 0\nnewmtl odd\nKd 1 1 1\nillum 5\n",
        );
        let obj = write(
            &d,
            "m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n\
             g a\nusemtl red\nf 1//1 2//1 3//1 4//1\ng b\nusemtl glow\nf 1 2 3\nusemtl odd\nf 1 3 4\n",
        );
        let mut warnings = Vec::new();
        let parts = load_obj(&obj, &mut warnings).unwrap();
        assert_eq!(parts.len(), 3, "{parts:?}");
        // The quad is triangulated into 2 triangles with the file's normals.
        assert_eq!(parts[0].mesh.triangles().len(), 2);
        assert!(parts[0].has_normals);
        let red = parts[0].material.unwrap();
        assert_eq!(red.diffuse(), Color::new(0.8, 0.0, 0.0));
        assert_eq!(red.shininess(), 20.0);
        // illum 0: constant colour Kd, carried as emission.
        let glow = parts[1].material.unwrap();
        assert_eq!(glow.emission(), Color::new(0.0, 1.0, 0.0));
        assert_eq!(glow.diffuse(), Color::BLACK);
        assert!(!parts[1].has_normals);
        assert!(warnings.iter().any(|w| w.contains("illum 5")), "{warnings:?}");
        let _ = std::fs::remove_dir_all(d);
    }

    /// What tobj reads differently from the format, or fails on without a line, is given to it
    /// normalised: trailing comments, `w` (dropped: the format gives polygon vertices none),
    /// colours on some vertices only, `vt u`; the model loads with the positions as written.
    #[test]
    fn tobj_gets_what_it_can_read() {
        let d = tmpdir("wild");
        let obj = write(
            &d,
            "wild.obj",
            "# a model\nv 0 0 0 # origin\nv 2 0 0 0.5\nv 0 1 0 1 0.5 0.25\nvt 0.5\nvt 1 0\nvt 0 1\n\
             f 1/1 2/2 3/3 # the face\n",
        );
        let parts = load_obj(&obj, &mut Vec::new()).unwrap();
        let p = parts[0].mesh.positions();
        assert_eq!(p.len(), 3);
        assert!(
            p.contains(&Vec3::new(2.0, 0.0, 0.0)) && p.contains(&Vec3::new(0.0, 1.0, 0.0)),
            "{p:?}"
        );
        let obj = write(&d, "nan.obj", "v 0 0 0\nv 1 0 0 nan\nv 0 1 0\nf 1 2 3\n");
        let e = load_obj(&obj, &mut Vec::new()).unwrap_err().to_string();
        assert!(e.contains("nan.obj:2:9: `v`"), "{e}");
        let _ = std::fs::remove_dir_all(d);
    }

    /// Text that is not UTF-8 is read as Latin-1 with a warning naming the line; a UTF-8
    /// byte-order mark is dropped; `l` and `p` statements are skipped with one warning counting
    /// them.
    #[test]
    fn latin1_bom_lines_and_points() {
        let d = tmpdir("enc");
        write(&d, "m.mtl", "newmtl caf\u{e9}\nKd 0.5 0.25 1\n");
        let mtl = d.join("m.mtl");
        let mut latin = std::fs::read(&mtl).unwrap();
        latin.retain(|&b| b != 0xc3); // é as one Latin-1 byte
        latin.iter_mut().for_each(|b| {
            if *b == 0xa9 {
                *b = 0xe9
            }
        });
        std::fs::write(&mtl, &latin).unwrap();
        let obj = write(
            &d,
            "m.obj",
            "\u{feff}mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\np 1\nusemtl caf\u{e9}\nf 1 2 3\n",
        );
        let mut bytes = std::fs::read(&obj).unwrap();
        let at = bytes.windows(2).position(|w| w == [0xc3, 0xa9]).unwrap();
        bytes.splice(at..at + 2, [0xe9]);
        std::fs::write(&obj, &bytes).unwrap();
        let mut w = Vec::new();
        let parts = load_obj(&obj, &mut w).unwrap();
        assert_eq!(
            parts[0].material.unwrap().diffuse(),
            phong_core::Color::new(0.5, 0.25, 1.0)
        );
        assert!(
            w.iter()
                .any(|w| w.contains("m.obj: not UTF-8 (line 8") && w.contains("Latin-1")),
            "{w:?}"
        );
        assert!(w.iter().any(|w| w.contains("m.mtl: not UTF-8 (line 1")), "{w:?}");
        assert!(
            w.iter()
                .any(|w| w.contains("1 line (`l`) and 2 point (`p`) statements skipped")),
            "{w:?}"
        );
        let _ = std::fs::remove_dir_all(d);
    }

    #[test]
    fn malformed_obj_names_line_and_column() {
        let d = tmpdir("bad");
        let obj = write(&d, "bad.obj", "v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n");
        let e = load_obj(&obj, &mut Vec::new()).unwrap_err().to_string();
        assert!(e.contains("bad.obj:3:5: `v`"), "{e}");
        let obj = write(&d, "range.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n");
        let e = load_obj(&obj, &mut Vec::new()).unwrap_err().to_string();
        assert!(
            e.contains("range.obj:4:7: `f`: vertex index 9 is out of range: 3 defined"),
            "{e}"
        );
        let obj = write(&d, "faceless.obj", "v 0 0 0\nv 1 0 0\n");
        let e = load_obj(&obj, &mut Vec::new()).unwrap_err().to_string();
        assert!(e.contains("faceless.obj:1:1: no faces"), "{e}");
        let obj = write(&d, "short.obj", "v 0 0\n");
        assert!(
            load_obj(&obj, &mut Vec::new())
                .unwrap_err()
                .to_string()
                .contains("short.obj:1:1")
        );
        // A missing MTL library: a warning naming the `mtllib` statement (its line, not a
        // comment's), and the default material.
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl gone\nf 1 2 3\n";
        for (name, text, want) in [
            (
                "comment.obj",
                format!("# see nope.mtl\nmtllib nope.mtl\n{tri}"),
                "comment.obj:2:8: `mtllib`",
            ),
            ("mtl.obj", format!("mtllib nope.mtl\n{tri}"), "mtl.obj:1:8: `mtllib`"),
        ] {
            let obj = write(&d, name, &text);
            let mut w = Vec::new();
            let parts = load_obj(&obj, &mut w).unwrap();
            assert!(parts[0].material.is_none(), "{name}");
            assert!(
                w.iter().any(|w| w.contains(want) && w.contains("nope.mtl")),
                "{name}: {w:?}"
            );
        }
        write(&d, "neg.mtl", "newmtl a\nKd 1 1 1\nNs -3\n");
        let obj = write(&d, "neg.obj", "mtllib neg.mtl\nv 0 0 0\n");
        let e = load_obj(&obj, &mut Vec::new()).unwrap_err().to_string();
        assert!(e.contains("neg.mtl:3:4: `Ns`: shininess must be >= 0"), "{e}");
        assert!(matches!(
            load_obj(&d.join("missing.obj"), &mut Vec::new()),
            Err(Error::Read { .. })
        ));
        let _ = std::fs::remove_dir_all(d);
    }

    #[test]
    fn negative_indices_resolve() {
        let d = tmpdir("neg");
        let obj = write(&d, "n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n");
        let parts = load_obj(&obj, &mut Vec::new()).unwrap();
        assert_eq!(parts[0].mesh.triangles().len(), 1);
        let _ = std::fs::remove_dir_all(d);
    }
}
