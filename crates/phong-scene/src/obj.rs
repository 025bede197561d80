//! Wavefront OBJ and MTL import, with tobj.
//!
//! tobj parses; before it, a line-by-line check of the OBJ (vertex records,
//! face indices) and of each MTL (colours, `Ns`, `d`, `illum`) finds
//! malformed input and reports its file, line and column, which tobj's
//! errors do not carry.
//!
//! MTL mapping: `Ka`, `Kd`, `Ks`, `Ke` → ambient, diffuse, specular,
//! emission; `Ns` → shininess (the exponent itself, 0..1000); `d` → alpha;
//! `illum` 0 → a constant colour `Kd` (as emission, nothing lit), 1 →
//! Lambert (no specular), 2 → Blinn-Phong; other models are rendered as 2
//! with a warning. Missing `Ka`/`Kd`/`Ks` take OpenGL's default material's values.

use crate::Error;
use glam::{DVec3, Vec3};
use phong_core::{Color, Material, Mesh};
use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// One group of an OBJ file with one material.
#[derive(Debug, Clone)]
pub struct ObjPart {
    /// `file:group`.
    pub name: String,
    /// Object-space geometry (normals from the file, or zero when it has none).
    pub mesh: Mesh,
    /// Its MTL material, if any.
    pub material: Option<Material>,
    /// True when the file gave normals for every vertex of this part.
    pub has_normals: bool,
    /// The point the positions are relative to, in the file's coordinates: a model far from
    /// the origin for its size is re-centred in f64 before its positions become f32 (so that
    /// it keeps its detail); zero otherwise. Every part of a model has the same.
    pub origin: DVec3,
}

/// The triangles of a tobj mesh's faces (`arities` empty when all are triangles), each
/// polygon triangulated by [`polygon::triangulate`](crate::polygon::triangulate).
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
            crate::polygon::triangulate(&corners)
                .into_iter()
                .map(|t| t.map(|k| face[k as usize])),
        );
    }
    tris
}

/// The material libraries an `mtllib` statement names: first the whole text as one name
/// (tried first by the caller: a name with spaces in it), then each name, names separated by
/// whitespace except where it is quoted (`"my file.mtl"`) or escaped (`my\ file.mtl`); other
/// backslashes are path separators (`textures\\a.mtl`).
fn mtl_names(text: &str) -> Vec<PathBuf> {
    let mut names = Vec::new();
    let mut whole = String::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = text.trim().chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => quoted = !quoted,
            '\\' if chars.peek().is_some_and(|n| n.is_whitespace()) => {
                let n = chars.next().unwrap_or(' ');
                cur.push(n);
                whole.push(n);
            }
            '\\' => {
                cur.push('/');
                whole.push('/');
            }
            c if c.is_whitespace() && !quoted => {
                if !cur.is_empty() {
                    names.push(PathBuf::from(std::mem::take(&mut cur)));
                }
                whole.push(c);
            }
            c => {
                cur.push(c);
                whole.push(c);
            }
        }
    }
    if !cur.is_empty() {
        names.push(PathBuf::from(cur));
    }
    let whole = PathBuf::from(whole.trim());
    if names.len() == 1 {
        return names;
    }
    names.insert(0, whole);
    names
}

/// A model file's text (see [`decode_text`]).
fn read(path: &Path, warnings: &mut Vec<String>) -> Result<String, Error> {
    let bytes = crate::read_bounded(path, phong_core::limits::MAX_MODEL_BYTES, "model (MAX_MODEL_BYTES)")?;
    Ok(decode_text(path, bytes, warnings))
}

/// Offset of the `n`th whitespace-separated field of `line` (0 = keyword), for columns.
fn field_offset(line: &str, n: usize) -> usize {
    let mut count = 0;
    let mut in_field = false;
    for (i, ch) in line.char_indices() {
        if ch.is_whitespace() {
            in_field = false;
        } else if !in_field {
            if count == n {
                return i;
            }
            count += 1;
            in_field = true;
        }
    }
    line.len()
}

struct Checker<'a> {
    path: &'a Path,
    src: &'a str,
}

impl Checker<'_> {
    fn err(&self, line_start: usize, line: &str, field: usize, key: &str, msg: String) -> Error {
        Error::at(
            self.path,
            self.src,
            line_start + field_offset(line, field),
            Some(key),
            msg,
        )
    }
}

fn lines(src: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut off = 0;
    src.split_inclusive('\n').map(move |l| {
        let start = off;
        off += l.len();
        (start, l.trim_end_matches(['\n', '\r']))
    })
}

/// A number as C's `strtod` reads it, which is how other loaders read OBJ numbers: Rust's
/// grammar (`1.e-3`, `.8e-001`, `1e+02`), else the longest prefix that is a decimal number
/// (`3.1+e2` is 3.1). The second value is true when characters were left over.
pub(crate) fn strtod(s: &str) -> Option<(f64, bool)> {
    if let Ok(x) = s.parse::<f64>() {
        return Some((x, false));
    }
    let b = s.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let int_end = digits(i);
    let mut n = int_end - i;
    i = int_end;
    if b.get(i) == Some(&b'.') {
        let frac_end = digits(i + 1);
        n += frac_end - i - 1;
        i = frac_end;
    }
    if n == 0 {
        return None;
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let j = i + 1 + usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let exp_end = digits(j);
        if exp_end > j {
            i = exp_end;
        }
    }
    s[..i].parse().ok().map(|x| (x, true))
}

/// An OBJ's text prepared for tobj, with what the preparation found.
struct Prepared {
    /// The text tobj reads, line for line the file's (so that locations stay right).
    text: String,
    /// What was skipped or repaired, for warnings.
    notes: Vec<String>,
    /// Subtracted from every position (in f64, before they become f32): the centre of a
    /// model that lies far from the origin, else zero.
    origin: DVec3,
}

/// Checks the OBJ records tobj would accept or reject without a location, and writes the
/// text as tobj reads it, line for line:
/// - numbers as `strtod` reads them, positions re-centred in f64 (see [`Prepared::origin`]);
/// - comments after a statement removed (tobj reads them as values);
/// - `v` records cut to `x y z` (a `w`, which the format gives no meaning for polygon
///   vertices and tobj divides by, is dropped; so are vertex colours, which phong does not use
///   and which tobj refuses unless every vertex has them), and `vt u` given its `v` of 0;
/// - faces with fewer than 3 vertices removed, and a face's texture or normal indices that
///   refer to nothing dropped from that face (its normals are then computed);
/// - `l` and `p` statements removed (phong draws surfaces).
///
/// A vertex index out of range, a malformed number or a non-finite coordinate is an error at
/// its line and column.
fn prepare_obj(path: &Path, src: &str) -> Result<Prepared, Error> {
    let c = Checker { path, src };
    fn words(line: &str) -> Vec<(usize, &str)> {
        let content = line.split('#').next().unwrap_or("");
        let mut out = Vec::new();
        let mut start = None;
        for (i, ch) in content.char_indices().chain([(content.len(), ' ')]) {
            match (ch.is_whitespace(), start) {
                (true, Some(s)) => {
                    out.push((s, &content[s..i]));
                    start = None;
                }
                (false, None) => start = Some(i),
                _ => {}
            }
        }
        out
    }
    // The positions, for the origin (malformed records are reported below).
    let origin = crate::formats::far_origin(lines(src).filter_map(|(_, line)| {
        let w = words(line);
        if w.first().map(|w| w.1) != Some("v") || w.len() < 4 {
            return None;
        }
        let p: Vec<f64> = w[1..4].iter().filter_map(|(_, t)| strtod(t).map(|x| x.0)).collect();
        (p.len() == 3 && p.iter().all(|x| x.is_finite())).then(|| DVec3::new(p[0], p[1], p[2]))
    }));
    let mut out = String::with_capacity(src.len() + 64);
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    let (mut short_faces, mut bad_refs, mut colours, mut lenient) = (0usize, 0usize, 0usize, None);
    let (mut lines_, mut points) = (0usize, 0usize);
    for (start, line) in lines(src) {
        let w = words(line);
        let Some(&(_, kw)) = w.first() else {
            // Blank or a comment: kept blank.
            out.push('\n');
            continue;
        };
        let field = |i: usize| start + w[i].0;
        let number = |i: usize, lenient: &mut Option<usize>| -> Result<f64, Error> {
            let t = w[i].1;
            match strtod(t) {
                Some((x, rest)) if x.is_finite() => {
                    if rest && lenient.is_none() {
                        *lenient = Some(crate::error::line_col(src, field(i)).0);
                    }
                    Ok(x)
                }
                Some(_) => Err(Error::at(
                    path,
                    src,
                    field(i),
                    Some(kw),
                    format!("{t:?} is not a finite number"),
                )),
                None => Err(Error::at(
                    path,
                    src,
                    field(i),
                    Some(kw),
                    format!("{t:?} is not a number"),
                )),
            }
        };
        match kw {
            "v" | "vn" | "vt" => {
                let need = if kw == "vt" { 1 } else { 3 };
                if w.len() - 1 < need {
                    return Err(c.err(
                        start,
                        line,
                        0,
                        kw,
                        format!("needs {need} numbers, found {}", w.len() - 1),
                    ));
                }
                let used = if kw == "vt" { (w.len() - 1).min(2) } else { 3 };
                let mut xs = Vec::with_capacity(3);
                for i in 1..=used {
                    xs.push(number(i, &mut lenient)?);
                }
                // A `v`'s `w` or colour, and a `vt`'s `w`, are not used, but a broken one is
                // a broken file.
                for i in used + 1..w.len().min(8) {
                    number(i, &mut lenient)?;
                }
                if kw == "v" && w.len() > 6 {
                    colours += 1;
                }
                out.push_str(kw);
                for (i, x) in xs.iter().enumerate() {
                    out.push(' ');
                    let o = if kw == "v" { origin[i] } else { 0.0 };
                    // The file's own digits where they read as they are; else the number as
                    // tobj will read it back (f32's shortest form).
                    if o == 0.0 && w[i + 1].1.parse::<f32>().is_ok() {
                        out.push_str(w[i + 1].1);
                    } else {
                        out.push_str(&((x - o) as f32).to_string());
                    }
                }
                if kw == "vt" && xs.len() == 1 {
                    out.push_str(" 0");
                }
                out.push('\n');
                match kw {
                    "v" => nv += 1,
                    "vt" => nt += 1,
                    _ => nn += 1,
                }
            }
            "f" => {
                if w.len() - 1 < 3 {
                    short_faces += 1;
                    out.push('\n');
                    continue;
                }
                let mut refs = Vec::with_capacity(w.len() - 1);
                let (mut keep_t, mut keep_n) = (true, true);
                for (i, &(_, r)) in w.iter().enumerate().skip(1) {
                    let parts: Vec<&str> = r.split('/').collect();
                    if parts.len() > 3 {
                        return Err(c.err(start, line, i, "f", format!("{r:?} is not v, v/vt, v//vn or v/vt/vn")));
                    }
                    let mut idx = [None; 3];
                    for (k, (p, (count, what))) in parts
                        .iter()
                        .zip([(nv, "vertex"), (nt, "texture coordinate"), (nn, "normal")])
                        .enumerate()
                    {
                        if p.is_empty() && k > 0 {
                            continue;
                        }
                        let v: i64 = p
                            .parse()
                            .map_err(|_| c.err(start, line, i, "f", format!("{r:?}: {p:?} is not an index")))?;
                        let resolved = if v < 0 { count + v + 1 } else { v };
                        if v == 0 || resolved < 1 || resolved > count {
                            if k == 0 {
                                return Err(c.err(
                                    start,
                                    line,
                                    i,
                                    "f",
                                    format!("{what} index {v} is out of range: {count} defined so far"),
                                ));
                            }
                            // A texture or normal index that refers to nothing: dropped.
                            bad_refs += 1;
                            if k == 1 {
                                keep_t = false;
                            } else {
                                keep_n = false;
                            }
                        }
                        idx[k] = Some(resolved);
                    }
                    refs.push(idx);
                }
                out.push('f');
                for [v, t, n] in refs {
                    let v = v.unwrap_or(0);
                    match (t.filter(|_| keep_t), n.filter(|_| keep_n)) {
                        (None, None) => out.push_str(&format!(" {v}")),
                        (Some(t), None) => out.push_str(&format!(" {v}/{t}")),
                        (None, Some(n)) => out.push_str(&format!(" {v}//{n}")),
                        (Some(t), Some(n)) => out.push_str(&format!(" {v}/{t}/{n}")),
                    }
                }
                out.push('\n');
            }
            "l" | "p" => {
                if kw == "l" {
                    lines_ += 1;
                } else {
                    points += 1;
                }
                out.push('\n');
            }
            _ => {
                let content = line.split('#').next().unwrap_or("");
                out.push_str(content.trim_end());
                out.push('\n');
            }
        }
    }
    let mut notes = Vec::new();
    let file = path.display();
    if let Some(l) = lenient {
        notes.push(format!(
            "{file}:{l}: numbers with trailing characters read as C's strtod reads them (the rest ignored)"
        ));
    }
    if short_faces > 0 {
        notes.push(format!(
            "{file}: {short_faces} faces with fewer than 3 vertices skipped"
        ));
    }
    if bad_refs > 0 {
        notes.push(format!(
            "{file}: {bad_refs} texture or normal indices refer to nothing: dropped from their faces"
        ));
    }
    if colours > 0 {
        notes.push(format!("{file}: vertex colours ({colours} vertices) are not used"));
    }
    if lines_ + points > 0 {
        notes.push(format!(
            "{file}: {lines_} line (`l`) and {points} point (`p`) statements skipped: phong draws surfaces"
        ));
    }
    Ok(Prepared {
        text: out,
        notes,
        origin,
    })
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

/// The MTL text as tobj can read it: a colour given as one number (`Kd 0.5`, which the format
/// allows for grey) written as three, since tobj's reader panics on fewer than three.
fn normalize_mtl(src: &str) -> String {
    let mut out = String::with_capacity(src.len() + 64);
    for line in src.split_inclusive('\n') {
        let content = line.split('#').next().unwrap_or("");
        let words: Vec<&str> = content.split_whitespace().collect();
        match words.as_slice() {
            [kw @ ("Ka" | "Kd" | "Ks" | "Ke"), v] => {
                out.push_str(&format!("{kw} {v} {v} {v}\n"));
            }
            _ => out.push_str(line),
        }
    }
    out
}

/// Checks an MTL file's values; returns the warnings (unsupported `illum`).
fn check_mtl(path: &Path, src: &str, warnings: &mut Vec<String>) -> Result<(), Error> {
    let c = Checker { path, src };
    let mut maps: Vec<&str> = Vec::new();
    let mut transparent = 0usize;
    for (start, line) in lines(src) {
        let content = line.split('#').next().unwrap_or("");
        let mut it = content.split_whitespace();
        let Some(kw) = it.next() else { continue };
        let rest: Vec<&str> = it.collect();
        if (kw.starts_with("map_") || matches!(kw, "bump" | "norm" | "disp" | "decal" | "refl")) && !maps.contains(&kw)
        {
            maps.push(kw);
        }
        let opacity = match (kw, rest.first().and_then(|x| x.parse::<f32>().ok())) {
            ("d", Some(d)) => Some(d),
            ("Tr", Some(t)) => Some(1.0 - t),
            _ => None,
        };
        if opacity.is_some_and(|o| o < 1.0) {
            transparent += 1;
        }
        let num = |i: usize| -> Result<f32, Error> {
            let f = rest
                .get(i)
                .ok_or_else(|| c.err(start, line, 0, kw, "is missing a number".into()))?;
            f.parse::<f32>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| c.err(start, line, i + 1, kw, format!("{f:?} is not a finite number")))
        };
        match kw {
            "Ka" | "Kd" | "Ks" | "Ke" => {
                if rest.first() == Some(&"spectral") || rest.first() == Some(&"xyz") {
                    return Err(c.err(start, line, 1, kw, "only RGB colours are supported".into()));
                }
                for i in 0..3 {
                    // "Kd r" alone means r = g = b.
                    if i > 0 && rest.len() == 1 {
                        break;
                    }
                    let x = num(i)?;
                    if x < 0.0 {
                        return Err(c.err(start, line, i + 1, kw, format!("must be >= 0, got {x}")));
                    }
                }
            }
            "Ns" => {
                let x = num(0)?;
                if x < 0.0 {
                    return Err(c.err(start, line, 1, kw, format!("shininess must be >= 0, got {x}")));
                }
            }
            "d" => {
                let x = num(0)?;
                if !(0.0..=1.0).contains(&x) {
                    return Err(c.err(start, line, 1, kw, format!("must be in [0, 1], got {x}")));
                }
            }
            "illum" => {
                let x = num(0)?;
                if x != x.trunc() || x < 0.0 {
                    return Err(c.err(start, line, 1, kw, format!("must be an integer >= 0, got {x}")));
                }
                if x > 2.0 {
                    let (l, _) = crate::error::line_col(src, start);
                    warnings.push(format!(
                        "{}:{l}: illum {x} is not supported; rendered as illum 2 (Blinn-Phong)",
                        path.display()
                    ));
                }
            }
            _ => {}
        }
    }
    if !maps.is_empty() {
        warnings.push(format!(
            "{}: texture maps are not rendered yet ({}): the materials' colours alone are used",
            path.display(),
            maps.join(", ")
        ));
    }
    if transparent > 0 {
        warnings.push(format!(
            "{}: {transparent} materials are transparent (`d` or `Tr`): drawn opaque (transparency is not rendered)",
            path.display()
        ));
    }
    Ok(())
}

fn to_material(m: &tobj::Material) -> Material {
    let def = Material::default();
    let c = |v: Option<[f32; 3]>, d: Color| v.map(Color::from_array).unwrap_or(d);
    let kd = c(m.diffuse, def.diffuse());
    let (ka, ks, ke) = (
        c(m.ambient, def.ambient()),
        c(m.specular, def.specular()),
        c(m.emissive, Color::BLACK),
    );
    let ns = m.shininess.unwrap_or(0.0);
    let built = match m.illumination_model.unwrap_or(2) {
        0 => Material::new(Color::BLACK, Color::BLACK, Color::BLACK, kd, 0.0),
        1 => Material::new(ka, kd, Color::BLACK, ke, ns),
        _ => Material::new(ka, kd, ks, ke, ns),
    };
    // Values were checked line by line before tobj parsed them.
    let built = built.unwrap_or_default();
    // `d` is the opacity; `Tr`, where there is no `d`, its complement (tinyobjloader's reading).
    let tr = m
        .unknown_param
        .get("Tr")
        .and_then(|t| t.trim().parse::<f32>().ok())
        .map(|t| 1.0 - t);
    built
        .with_alpha(m.dissolve.or(tr).unwrap_or(1.0).clamp(0.0, 1.0))
        .unwrap_or(built)
}

/// Loads an OBJ file and its MTL materials: one part per group and material.
pub fn load_obj(path: &Path, warnings: &mut Vec<String>) -> Result<Vec<ObjPart>, Error> {
    load_obj_sources(path, warnings, &mut Vec::new())
}

/// [`load_obj`], adding every file it reads (the OBJ, its MTL libraries) to `sources`.
pub fn load_obj_sources(
    path: &Path,
    warnings: &mut Vec<String>,
    sources: &mut Vec<PathBuf>,
) -> Result<Vec<ObjPart>, Error> {
    let src = read(path, warnings)?;
    sources.push(path.to_path_buf());
    obj_from_text(path, &src, warnings, sources)
}

/// An OBJ's text `src` (of `path`) with its MTL libraries read beside it, each added to
/// `sources`.
pub(crate) fn obj_from_text(
    path: &Path,
    src: &str,
    warnings: &mut Vec<String>,
    sources: &mut Vec<PathBuf>,
) -> Result<Vec<ObjPart>, Error> {
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let read_mtl = std::cell::RefCell::new(Vec::new());
    let latin1 = std::cell::RefCell::new(Vec::new());
    let out = load_obj_text(
        path,
        src,
        &|mtl| {
            let p = dir.join(mtl);
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
        warnings,
    );
    warnings.extend(latin1.into_inner());
    sources.extend(read_mtl.into_inner());
    out
}

/// [`load_obj`] of an OBJ's text `src` (named `path` in messages), its MTL libraries read by
/// `read_mtl` (given the name the `mtllib` line gives).
pub fn load_obj_text(
    path: &Path,
    src: &str,
    read_mtl: &dyn Fn(&Path) -> std::io::Result<String>,
    warnings: &mut Vec<String>,
) -> Result<Vec<ObjPart>, Error> {
    let prepared = prepare_obj(path, src)?;
    warnings.extend(prepared.notes.iter().cloned());
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mtl_error: std::cell::RefCell<Option<Error>> = Default::default();
    let mtl_warnings: std::cell::RefCell<Vec<String>> = Default::default();
    let opts = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = tobj::load_obj_buf(&mut BufReader::new(prepared.text.as_bytes()), &opts, |mtl: &Path| {
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
                    if let Err(e) = check_mtl(&p, &t, &mut mtl_warnings.borrow_mut()) {
                        *mtl_error.borrow_mut() = Some(e);
                        return Err(tobj::LoadError::MaterialParseError);
                    }
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
    });
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    warnings.extend(mtl_warnings.into_inner());
    let (models, materials) = loaded.map_err(|e| {
        // tobj names no line: point at the first statement of the kind it could not read.
        let kw = match e {
            tobj::LoadError::PositionParseError
            | tobj::LoadError::ScalingByZeroError
            | tobj::LoadError::ColorParseError => "v",
            tobj::LoadError::NormalParseError => "vn",
            tobj::LoadError::TexcoordParseError => "vt",
            tobj::LoadError::MaterialParseError => "usemtl",
            tobj::LoadError::InvalidObjectName => "o",
            _ => "f",
        };
        let at = lines(src)
            .find(|(_, l)| l.split_whitespace().next() == Some(kw))
            .map_or(0, |(start, _)| start);
        Error::at(
            path,
            src,
            at,
            Some(kw),
            format!("malformed OBJ: {e} (tobj does not say where; the first `{kw}` statement is shown)"),
        )
    })?;
    let materials: Vec<tobj::Material> = materials.unwrap_or_default();
    let materials: Vec<Material> = materials.iter().map(to_material).collect();
    let file = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut parts = Vec::new();
    for model in models {
        let m = &model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        let has_normals = m.normals.len() == m.positions.len();
        let normals = if has_normals {
            m.normals
                .chunks_exact(3)
                .map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or_zero())
                .collect()
        } else {
            vec![Vec3::ZERO; positions.len()]
        };
        let tris = polygons_to_triangles(&positions, &m.indices, &m.face_arities);
        let mesh = Mesh::new(positions, normals, tris)
            .map_err(|e| Error::at(path, src, 0, None, format!("group {}: {e}", model.name)))?;
        parts.push(ObjPart {
            name: format!("{file}:{}", model.name),
            mesh,
            material: m.material_id.and_then(|i| materials.get(i).copied()),
            has_normals,
            origin: prepared.origin,
        });
    }
    if parts.is_empty() {
        return Err(Error::at(
            path,
            src,
            0,
            None,
            format!(
                "no faces (`f` records with 3 or more vertices): nothing to render{}",
                prepared
                    .notes
                    .iter()
                    .map(|n| {
                        let file = format!("{}: ", path.display());
                        format!("; {}", n.strip_prefix(&file).unwrap_or(n))
                    })
                    .collect::<String>()
            ),
        ));
    }
    // Merge parts that share a material within the same group name.
    let mut merged: Vec<ObjPart> = Vec::new();
    let mut index: HashMap<(String, Option<[u32; 4]>), usize> = HashMap::new();
    for p in parts {
        let key = (
            p.name.clone(),
            p.material.map(|m| {
                [
                    m.diffuse().r.to_bits(),
                    m.diffuse().g.to_bits(),
                    m.specular().r.to_bits(),
                    m.shininess().to_bits(),
                ]
            }),
        );
        match index.get(&key) {
            Some(&i) if merged[i].has_normals == p.has_normals => merged[i].mesh.append(&p.mesh),
            _ => {
                index.insert(key, merged.len());
                merged.push(p);
            }
        }
    }
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let parts = crate::load_model(&obj, &mut w).unwrap();
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
