//! The OBJ reader: one pass over the text, checking every record as it goes (each error at its
//! line and column) and filling the vertex arrays, then each group's faces exported as tobj's
//! single-index meshes (so that the MTL handling and the parts built from them stay tobj's).
//!
//! What it reads as other loaders read it: numbers as C's `strtod` (the rest of a word
//! ignored, with a note), positions re-centred in f64 where the model lies far from the
//! origin, a `v`'s `w` ignored, vertex colours where every `v` has `x y z r g b`, `vt u` with
//! `v = 0`, negative indices, faces of fewer than 3 vertices and `l`/`p` statements skipped,
//! texture or normal indices that refer to nothing dropped from their face. Groups (`o`, `g`)
//! and materials (`usemtl`) split the faces into models as tobj splits them.

use super::text::{
    Checker, NO_MATERIAL, lines, plain_decimal, plain_decimal_at, plain_index, slashed, strtod, vertex_kind, words,
};
use crate::Error;
use crate::beside::map;
use glam::DVec3;
use rustc_hash::FxHashMap;
use std::path::Path;

/// Where a face's texture or normal index is absent.
const MISSING: u32 = u32::MAX;

/// What the pass found, tobj's way.
pub(super) struct Read {
    /// The groups' meshes (tobj's single index), in file order; empty ones included.
    pub models: Vec<tobj::Model>,
    /// The libraries' materials, or the last library's error where none was read.
    pub materials: Result<Vec<tobj::Material>, tobj::LoadError>,
    /// What was skipped or repaired, for warnings.
    pub notes: Vec<String>,
    /// Subtracted from every position (see `ModelPart::origin`).
    pub origin: DVec3,
    /// The names `usemtl` statements give (as their lines give them).
    pub used: Vec<String>,
}

/// A group's faces until it ends: `(v, vt, vn)` 0-based per corner, and each face's corners.
#[derive(Default)]
struct Group {
    name: String,
    material: Option<usize>,
    corners: Vec<[u32; 3]>,
    arities: Vec<u32>,
}

/// A pass over a run of the file's lines (the whole file, or one of the chunks read side by
/// side): the vertex arrays, the faces, the statements whose effect depends on what came
/// before them (kept for the replay in file order), what to note.
struct Reader<'a> {
    path: &'a Path,
    src: &'a str,
    /// The `v`, `vt` and `vn` statements before the run (for its faces' indices).
    base: [i64; 3],
    /// Per `v`: its coordinates in f64, the f32 its own digits read as (NaN where they do
    /// not), and its colour (used where every `v` has exactly six numbers).
    xyz: Vec<DVec3>,
    direct: Vec<[f32; 3]>,
    colours: Vec<[f32; 3]>,
    seven: bool,
    texcoords: Vec<f32>,
    normals: Vec<f32>,
    /// The faces' corners and sizes, in file order.
    corners: Vec<[u32; 3]>,
    arities: Vec<u32>,
    /// Each group or material statement, after how many corners and faces it came.
    events: Vec<(usize, usize, Event<'a>)>,
    /// The first line with a number read as strtod reads it (the rest of the word ignored).
    lenient: Option<usize>,
    short_faces: usize,
    bad_refs: usize,
    long_v: usize,
    lines: usize,
    points: usize,
    bad_colours: usize,
    unnamed: usize,
}

/// A statement that splits the faces into groups or loads materials, as a pass keeps it.
enum Event<'a> {
    /// `o` or `g`, its statement without comment or trailing space.
    Group(&'a str),
    /// `usemtl`, as its line gives it (`usemtl NAME`).
    Usemtl(String),
    /// `mtllib`, the library's path.
    Mtllib(&'a str),
}

/// The groups so far and the materials, built by replaying the passes' faces and events in
/// file order.
struct Groups {
    groups: Vec<Group>,
    current: Group,
    materials: Vec<tobj::Material>,
    names: FxHashMap<String, usize>,
    mtl_error: Option<tobj::LoadError>,
    used: Vec<String>,
}

/// One statement: where its line starts, the line, its words.
struct Statement<'a, 'w> {
    start: usize,
    line: &'a str,
    w: &'w [(usize, &'a str)],
}

impl<'a> Statement<'a, '_> {
    fn kw(&self) -> &str {
        self.w[0].1
    }

    /// The statement before any comment, without trailing space (as tobj was given it).
    fn content(&self) -> &'a str {
        self.line.split('#').next().unwrap_or("").trim_end()
    }
}

impl<'a> Reader<'a> {
    fn err(&self, s: &Statement, field: usize, msg: String) -> Error {
        Checker {
            path: self.path,
            src: self.src,
        }
        .err(s.start, s.line, field, s.kw(), msg)
    }

    /// Word `i` as a finite number (as strtod reads it), or an error at it.
    fn number(&mut self, s: &Statement, i: usize) -> Result<f64, Error> {
        let t = s.w[i].1;
        let at = s.start + s.w[i].0;
        match strtod(t) {
            Some((x, rest)) if x.is_finite() => {
                if rest && self.lenient.is_none() {
                    self.lenient = Some(crate::error::line_col(self.src, at).0);
                }
                Ok(x)
            }
            Some(_) => Err(Error::at(
                self.path,
                self.src,
                at,
                Some(s.kw()),
                format!("{t:?} is not a finite number"),
            )),
            None => Err(Error::at(
                self.path,
                self.src,
                at,
                Some(s.kw()),
                format!("{t:?} is not a number"),
            )),
        }
    }

    /// `v`, `vt` or `vn`.
    fn vertex(&mut self, s: &Statement) -> Result<(), Error> {
        let (kw, w) = (s.kw(), s.w);
        let need = if kw == "vt" { 1 } else { 3 };
        if w.len() - 1 < need {
            return Err(self.err(s, 0, format!("needs {need} numbers, found {}", w.len() - 1)));
        }
        let used_n = if kw == "vt" { (w.len() - 1).min(2) } else { 3 };
        let mut xs = [0.0f64; 3];
        let mut own = [f32::NAN; 3];
        for i in 1..=used_n {
            // The commonest case without a general parse: a short plain decimal.
            if let Some((x, f)) = plain_decimal(w[i].1) {
                (xs[i - 1], own[i - 1]) = (x, f);
                continue;
            }
            // The common case in one parse: the word is a finite f32 as it stands.
            match w[i].1.parse::<f32>() {
                Ok(v) if v.is_finite() && kw != "v" => {
                    own[i - 1] = v;
                    continue;
                }
                Ok(v) => own[i - 1] = v,
                Err(_) => {}
            }
            xs[i - 1] = self.number(s, i)?;
        }
        // A `v`'s `w` or colour, and a `vt`'s `w`, are not used, but a broken one is a broken
        // file.
        let mut rgb = [0.0f32; 3];
        for (i, (_, t)) in w.iter().enumerate().take(8).skip(used_n + 1) {
            // A colour that is no finite number (`nan`): the colours are dropped, the
            // positions kept.
            if kw == "v" && w.len() == 7 && i >= 4 && strtod(t).is_some_and(|(x, _)| !x.is_finite()) {
                self.bad_colours += 1;
                self.seven = false;
                continue;
            }
            let x = self.number(s, i)?;
            if kw == "v" && (4..7).contains(&i) {
                rgb[i - 4] = x as f32;
            }
        }
        // Where the word is not an f32 as it stands, the number as strtod reads it.
        let value = |k: usize| if own[k].is_nan() { xs[k] as f32 } else { own[k] };
        match kw {
            "v" => {
                if w.len() > 6 {
                    self.long_v += 1;
                }
                self.seven &= w.len() == 7;
                self.xyz.push(DVec3::from_array(xs));
                self.direct.push(own);
                self.colours.push(rgb);
            }
            "vt" => self
                .texcoords
                .extend([value(0), if used_n == 2 { value(1) } else { 0.0 }]),
            _ => self.normals.extend((0..3).map(value)),
        }
        Ok(())
    }

    /// `f`: its corners as 0-based `(v, vt, vn)`.
    fn face(&mut self, s: &Statement) -> Result<(), Error> {
        let w = s.w;
        if w.len() - 1 < 3 {
            self.short_faces += 1;
            return Ok(());
        }
        let first = self.corners.len();
        let (mut keep_t, mut keep_n) = (true, true);
        let counts = [
            self.base[0] + self.xyz.len() as i64,
            self.base[1] + (self.texcoords.len() / 2) as i64,
            self.base[2] + (self.normals.len() / 3) as i64,
        ];
        for (i, &(_, r)) in w.iter().enumerate().skip(1) {
            if r.bytes().filter(|&b| b == b'/').count() > 2 {
                return Err(self.err(s, i, format!("{r:?} is not v, v/vt, v//vn or v/vt/vn")));
            }
            let mut idx = [MISSING; 3];
            for (k, p) in slashed(r).enumerate() {
                if p.is_empty() && k > 0 {
                    continue;
                }
                let v: i64 = match plain_index(p) {
                    Some(v) => v,
                    None => p
                        .parse()
                        .map_err(|_| self.err(s, i, format!("{r:?}: {p:?} is not an index")))?,
                };
                let count = counts[k];
                let resolved = if v < 0 { count + v + 1 } else { v };
                if v == 0 || resolved < 1 || resolved > count {
                    if k == 0 {
                        return Err(self.err(
                            s,
                            i,
                            format!("vertex index {v} is out of range: {count} defined so far"),
                        ));
                    }
                    // A texture or normal index that refers to nothing: dropped from the face.
                    self.bad_refs += 1;
                    if k == 1 {
                        keep_t = false;
                    } else {
                        keep_n = false;
                    }
                }
                idx[k] = (resolved - 1).clamp(0, i64::from(u32::MAX - 1)) as u32;
            }
            self.corners.push(idx);
        }
        for corner in &mut self.corners[first..] {
            if !keep_t {
                corner[1] = MISSING;
            }
            if !keep_n {
                corner[2] = MISSING;
            }
        }
        self.arities.push((w.len() - 1) as u32);
        Ok(())
    }

    /// A `v` of three plain decimals (`rest`: after `v `, words apart by spaces) as
    /// [`Reader::vertex`] reads it; false, nothing read, for any other.
    fn plain_vertex(&mut self, rest: &[u8]) -> bool {
        let mut xs = [0.0f64; 3];
        let mut own = [0.0f32; 3];
        let words = each_word(rest, 3, |n, i| {
            let (x, f, end) = plain_decimal_at(rest, i)?;
            (xs[n], own[n]) = (x, f);
            Some(end)
        });
        if words != Some(3) {
            return false;
        }
        self.seven = false;
        self.xyz.push(DVec3::from_array(xs));
        self.direct.push(own);
        self.colours.push([0.0; 3]);
        true
    }

    /// An `f` of three to eight plain positive vertex indices, each naming a vertex defined
    /// so far (`rest`: after `f `, words apart by spaces), as [`Reader::face`] reads it;
    /// false, nothing read, for any other.
    fn plain_face(&mut self, rest: &[u8]) -> bool {
        let count = self.base[0] + self.xyz.len() as i64;
        let mut corners = [0u32; 8];
        // Each a word of at most 18 digits.
        let words = each_word(rest, corners.len(), |n, start| {
            let (mut i, mut v) = (start, 0i64);
            while i < rest.len() && rest[i].is_ascii_digit() {
                if i - start == 18 {
                    return None;
                }
                v = v * 10 + i64::from(rest[i] - b'0');
                i += 1;
            }
            if i == start || v < 1 || v > count {
                return None;
            }
            corners[n] = (v - 1) as u32;
            Some(i)
        });
        let Some(n) = words.filter(|&n| n >= 3) else {
            return false;
        };
        self.corners.extend(corners[..n].iter().map(|&v| [v, MISSING, MISSING]));
        self.arities.push(n as u32);
        true
    }

    /// A group or material statement, kept for the replay.
    fn event(&mut self, e: Event<'a>) {
        self.events.push((self.corners.len(), self.arities.len(), e));
    }

    /// `usemtl`'s statement as its line gives it, checked (the replay applies it).
    fn usemtl(&mut self, s: &Statement) -> Result<String, Error> {
        let statement = if s.w.len() == 1 {
            // No name (assimp's test files): the default material from here on, as a name
            // that no library defines gives it.
            self.unnamed += 1;
            format!("usemtl {NO_MATERIAL}")
        } else {
            s.content().to_string()
        };
        if statement.split_once(' ').unwrap_or_default().1.trim().is_empty() {
            return Err(self.err(
                s,
                0,
                "malformed OBJ: `usemtl` and its name must be separated by a space".into(),
            ));
        }
        Ok(statement)
    }

    /// What was skipped or repaired, for warnings.
    fn notes(&self, keep_colours: bool) -> Vec<String> {
        let file = self.path.display();
        let mut notes = Vec::new();
        if let Some(l) = self.lenient {
            notes.push(format!(
                "{file}:{l}: numbers with trailing characters read as C's strtod reads them (the rest ignored)"
            ));
        }
        if self.short_faces > 0 {
            notes.push(format!(
                "{file}: {} faces with fewer than 3 vertices skipped",
                self.short_faces
            ));
        }
        if self.bad_refs > 0 {
            notes.push(format!(
                "{file}: {} texture or normal indices refer to nothing: dropped from their faces",
                self.bad_refs
            ));
        }
        if self.unnamed > 0 {
            notes.push(format!(
                "{file}: {} `usemtl` statements name no material: the default material there",
                self.unnamed
            ));
        }
        if self.bad_colours > 0 {
            notes.push(format!(
                "{file}: vertex colours are not used: {} colour values are not finite numbers",
                self.bad_colours
            ));
        } else if self.long_v > 0 && !keep_colours {
            notes.push(format!(
                "{file}: vertex colours ({} vertices) are not used: not every vertex has `x y z r g b`",
                self.long_v
            ));
        }
        if self.lines + self.points > 0 {
            notes.push(format!(
                "{file}: {} line (`l`) and {} point (`p`) statements skipped: phong draws surfaces",
                self.lines, self.points
            ));
        }
        notes
    }

    /// The groups as tobj's meshes, their positions re-centred, and what was noted.
    fn finish(self, mut g: Groups) -> Read {
        // The last group, as tobj ends a file (empty where the file ends in a group's name).
        g.groups.push(std::mem::take(&mut g.current));
        // The file's own f32 where its digits read as one and no re-centring is needed, else
        // the f64 value moved to the origin, then rounded.
        let origin = crate::models::far_origin(self.xyz.iter().copied());
        let keep_colours = self.seven && !self.xyz.is_empty();
        // (A loop into a sized vector: a flattening iterator's `collect` grew it element by
        // element.)
        let mut positions: Vec<f32> = Vec::with_capacity(3 * self.xyz.len());
        for (x, own) in self.xyz.iter().zip(&self.direct) {
            for k in 0..3 {
                positions.push(if origin[k] == 0.0 && !own[k].is_nan() {
                    own[k]
                } else {
                    (x[k] - origin[k]) as f32
                });
            }
        }
        let colours: Vec<f32> = if keep_colours {
            self.colours.as_flattened().to_vec()
        } else {
            Vec::new()
        };
        let notes = self.notes(keep_colours);
        let models = g
            .groups
            .into_iter()
            .map(|g| export(g, &positions, &colours, &self.texcoords, &self.normals))
            .collect();
        let materials = match (g.materials.is_empty(), g.mtl_error) {
            (true, Some(e)) => Err(e),
            _ => Ok(g.materials),
        };
        Read {
            models,
            materials,
            notes,
            origin,
            used: g.used,
        }
    }

    /// The next pass's vertex arrays and counts after this one's (its faces and events
    /// already replayed).
    fn append(&mut self, mut r: Reader) {
        self.xyz.append(&mut r.xyz);
        self.direct.append(&mut r.direct);
        self.colours.append(&mut r.colours);
        self.texcoords.append(&mut r.texcoords);
        self.normals.append(&mut r.normals);
        self.seven &= r.seven;
        self.lenient = self.lenient.or(r.lenient);
        self.short_faces += r.short_faces;
        self.bad_refs += r.bad_refs;
        self.long_v += r.long_v;
        self.lines += r.lines;
        self.points += r.points;
        self.bad_colours += r.bad_colours;
        self.unnamed += r.unnamed;
    }
}

impl Groups {
    /// A pass's faces and events, in file order, after those of the passes before it.
    fn replay(&mut self, r: &mut Reader, load_mtl: &mut dyn FnMut(&Path) -> tobj::MTLLoadResult) {
        let (mut c0, mut a0) = (0, 0);
        self.current.corners.reserve(r.corners.len());
        self.current.arities.reserve(r.arities.len());
        for (c, a, e) in std::mem::take(&mut r.events) {
            self.current.corners.extend_from_slice(&r.corners[c0..c]);
            self.current.arities.extend_from_slice(&r.arities[a0..a]);
            (c0, a0) = (c, a);
            match e {
                Event::Group(content) => self.group(content),
                Event::Usemtl(statement) => self.usemtl(statement),
                Event::Mtllib(lib) => self.mtllib(lib, load_mtl),
            }
        }
        if c0 == 0 && self.current.corners.is_empty() && self.current.arities.is_empty() {
            // (The common case, one group: its faces moved, not copied.)
            self.current.corners = std::mem::take(&mut r.corners);
            self.current.arities = std::mem::take(&mut r.arities);
        } else {
            self.current.corners.extend_from_slice(&r.corners[c0..]);
            self.current.arities.extend_from_slice(&r.arities[a0..]);
        }
    }

    /// `o` or `g` (`content`: its statement without comment or trailing space): a new group
    /// (the faces so far are the last one's), named as tobj names it: the line after its
    /// first character, trimmed.
    fn group(&mut self, content: &str) {
        if !self.current.corners.is_empty() {
            let material = self.current.material;
            self.groups.push(std::mem::take(&mut self.current));
            self.current.material = material;
        }
        let size = content.chars().next().map_or(0, char::len_utf8);
        self.current.name = content[size..].trim().to_owned();
        if self.current.name.is_empty() {
            self.current.name = "unnamed_object".into();
        }
    }

    /// `usemtl` (its checked statement): the faces from here on take the material (a group
    /// of its own where it changes).
    fn usemtl(&mut self, statement: String) {
        let name = statement.split_once(' ').unwrap_or_default().1.trim();
        let material = self.names.get(name).copied();
        if self.current.material != material && !self.current.corners.is_empty() {
            let name = self.current.name.clone();
            self.groups.push(std::mem::take(&mut self.current));
            self.current.name = name;
        }
        self.current.material = material;
        self.used.push(statement);
    }

    /// `mtllib`: the library's materials, after those read so far.
    fn mtllib(&mut self, lib: &str, load_mtl: &mut dyn FnMut(&Path) -> tobj::MTLLoadResult) {
        match load_mtl(Path::new(lib)) {
            Ok((mut mats, map)) => {
                let offset = self.materials.len();
                self.materials.append(&mut mats);
                for (k, v) in map {
                    self.names.insert(k, v + offset);
                }
            }
            Err(e) => self.mtl_error = Some(e),
        }
    }
}

/// Reads the OBJ text `src` (continuation lines already joined), its `mtllib` statements
/// given to `load_mtl` as tobj gives them. A large file is read in chunks of lines side by
/// side (a chunk's faces resolved against the vertices counted before it), then its groups
/// and materials replayed in file order: the same result, and the same first error, as one
/// pass.
pub(super) fn read_obj(
    path: &Path,
    src: &str,
    load_mtl: &mut dyn FnMut(&Path) -> tobj::MTLLoadResult,
) -> Result<Read, Error> {
    /// Bytes a chunk has at least: a 256 KiB chunk reads in about 1 ms here, against a thread's
    /// start of tens of µs (the threshold itself not tuned by measurement).
    const CHUNK: usize = 1 << 18;
    let threads = crate::beside::cores().min(8);
    read_in_chunks(path, src, load_mtl, (src.len() / CHUNK).clamp(1, threads))
}

/// [`read_obj`] with the text cut into (at most) `chunks` runs of whole lines.
fn read_in_chunks(
    path: &Path,
    src: &str,
    load_mtl: &mut dyn FnMut(&Path) -> tobj::MTLLoadResult,
    chunks: usize,
) -> Result<Read, Error> {
    let runs = cut_lines(src, chunks);
    let passes: Vec<(Reader, Option<Error>)> = if runs.len() == 1 {
        vec![pass(path, src, runs[0], [0; 3])]
    } else {
        // The vertex statements before each run, then the runs read side by side, a thread a
        // run. (The last run's count is no run's base.)
        let mut counts = map(runs[..runs.len() - 1].to_vec(), runs.len(), |run| {
            vertex_counts(&src[run.0..run.1])
        });
        counts.push([0; 3]);
        let mut base = [0i64; 3];
        let bases: Vec<(usize, usize, [i64; 3])> = runs
            .iter()
            .zip(&counts)
            .map(|(&(start, end), c)| {
                let b = base;
                (0..3).for_each(|k| base[k] += c[k]);
                (start, end, b)
            })
            .collect();
        map(bases, runs.len(), |(start, end, base)| {
            pass(path, src, (start, end), base)
        })
    };
    let mut g = Groups {
        groups: Vec::new(),
        current: Group {
            name: "unnamed_object".into(),
            ..Group::default()
        },
        materials: Vec::new(),
        names: FxHashMap::default(),
        mtl_error: None,
        used: Vec::new(),
    };
    let mut all: Option<Reader> = None;
    for (mut r, error) in passes {
        g.replay(&mut r, load_mtl);
        // A pass stops at its first error: the file's first, the passes before it clean.
        if let Some(e) = error {
            return Err(e);
        }
        match &mut all {
            Some(a) => a.append(r),
            None => all = Some(r),
        }
    }
    Ok(all.expect("at least one run").finish(g))
}

/// `src` cut into at most `n` runs `(start, end)` of whole lines, in order, none empty
/// (one, empty, for an empty text).
fn cut_lines(src: &str, n: usize) -> Vec<(usize, usize)> {
    let mut runs = Vec::with_capacity(n);
    let mut start = 0;
    for k in 1..n {
        let at = (src.len() * k / n).max(start);
        let end = memchr::memchr(b'\n', &src.as_bytes()[at..]).map_or(src.len(), |i| at + i + 1);
        if end > start && end < src.len() {
            runs.push((start, end));
            start = end;
        }
    }
    runs.push((start, src.len()));
    runs
}

/// The `v`, `vt` and `vn` statements of a run of lines (each adds one vertex, or the file
/// has an error there, which comes first).
fn vertex_counts(run: &str) -> [i64; 3] {
    let mut counts = [0i64; 3];
    let mut w: Vec<(usize, &str)> = Vec::with_capacity(16);
    for (_, line) in lines(run) {
        let kind = vertex_kind(line).unwrap_or_else(|| {
            words(line, &mut w);
            w.first()
                .and_then(|&(_, kw)| ["v", "vt", "vn"].iter().position(|&v| v == kw))
        });
        if let Some(k) = kind {
            counts[k] += 1;
        }
    }
    counts
}

/// One pass over the lines `src[run.0..run.1]`, with `base` vertex statements before them:
/// the pass, and the error it stopped at.
fn pass<'a>(path: &'a Path, src: &'a str, run: (usize, usize), base: [i64; 3]) -> (Reader<'a>, Option<Error>) {
    // Room for as many vertices and faces as the run has lines, three corners a face: no
    // growth (each a copy of what was read) for the common files; memory not written to is
    // only reserved.
    let lines = newlines(&src.as_bytes()[run.0..run.1]) + 1;
    let mut r = Reader {
        path,
        src,
        base,
        xyz: Vec::with_capacity(lines),
        direct: Vec::with_capacity(lines),
        colours: Vec::new(),
        seven: true,
        texcoords: Vec::new(),
        normals: Vec::new(),
        corners: Vec::with_capacity(3 * lines),
        arities: Vec::with_capacity(lines),
        events: Vec::new(),
        lenient: None,
        short_faces: 0,
        bad_refs: 0,
        long_v: 0,
        lines: 0,
        points: 0,
        bad_colours: 0,
        unnamed: 0,
    };
    let error = statements(&mut r, run).err();
    (r, error)
}

/// The words of `rest` (apart by spaces), each read where it starts, in one pass over the
/// line: `read(n, i)` reads word `n` at `rest[i]` and returns where it ended, which must be a
/// space or the line's end. The number of words, or `None` where a word is refused or there
/// are more than `most`.
#[inline(always)]
fn each_word(rest: &[u8], most: usize, mut read: impl FnMut(usize, usize) -> Option<usize>) -> Option<usize> {
    let (mut n, mut i) = (0, 0);
    loop {
        while i < rest.len() && rest[i] == b' ' {
            i += 1;
        }
        if i == rest.len() {
            return Some(n);
        }
        if n == most {
            return None;
        }
        let end = read(n, i)?;
        if end < rest.len() && rest[end] != b' ' {
            return None;
        }
        (i, n) = (end, n + 1);
    }
}

/// The `\n` bytes of `bytes`, counted in 8-bit lanes (blocks of 255 bytes, so that no lane
/// wraps): a few instructions a 32 bytes, where a count in `usize` costs a few a byte.
fn newlines(bytes: &[u8]) -> usize {
    bytes
        .chunks(255)
        .map(|block| usize::from(block.iter().fold(0u8, |n, &b| n.wrapping_add(u8::from(b == b'\n')))))
        .sum()
}

/// The statements of a pass's lines, until the first error.
fn statements<'a>(r: &mut Reader<'a>, run: (usize, usize)) -> Result<(), Error> {
    let src = r.src;
    let mut w: Vec<(usize, &str)> = Vec::with_capacity(16);
    for (start, line) in lines(&src[run.0..run.1]) {
        // The commonest lines (`v x y z` of plain decimals, `f a b c` of plain indices) read
        // without splitting them into words: what the general path would read.
        if let [kw @ (b'v' | b'f'), b' ', rest @ ..] = line.as_bytes()
            && (if *kw == b'v' {
                r.plain_vertex(rest)
            } else {
                r.plain_face(rest)
            })
        {
            continue;
        }
        words(line, &mut w);
        if w.is_empty() {
            continue;
        }
        let s = Statement {
            start: run.0 + start,
            line,
            w: &w,
        };
        match s.kw() {
            "v" | "vn" | "vt" => r.vertex(&s)?,
            "f" => r.face(&s)?,
            "l" => r.lines += 1,
            "p" => r.points += 1,
            "o" | "g" => r.event(Event::Group(s.content())),
            "usemtl" => {
                let statement = r.usemtl(&s)?;
                r.event(Event::Usemtl(statement));
            }
            "mtllib" => r.event(Event::Mtllib(s.content().split_once(' ').unwrap_or_default().1.trim())),
            _ => {}
        }
    }
    Ok(())
}

/// A group's faces as tobj's single-index mesh: one vertex per distinct `(v, vt, vn)`, in
/// order of first use; `face_arities` empty where every face is a triangle.
fn export(g: Group, positions: &[f32], colours: &[f32], texcoords: &[f32], normals: &[f32]) -> tobj::Model {
    let mut mesh = tobj::Mesh {
        material_id: g.material,
        ..Default::default()
    };
    let plain = g.corners.iter().all(|c| c[1] == MISSING && c[2] == MISSING);
    // Where corners are positions alone, a table by position; else a hash map.
    let mut by_v = if plain {
        vec![u32::MAX; positions.len() / 3]
    } else {
        Vec::new()
    };
    let mut by_key: FxHashMap<[u32; 3], u32> = FxHashMap::default();
    let n = g.corners.len();
    mesh.indices.reserve(n);
    // At most one vertex a corner, and (positions alone) one a position.
    let most = if plain { n.min(positions.len() / 3) } else { n };
    mesh.positions.reserve(3 * most);
    for c in &g.corners {
        let slot = if plain {
            &mut by_v[c[0] as usize]
        } else {
            by_key.entry(*c).or_insert(u32::MAX)
        };
        if *slot == u32::MAX {
            *slot = (mesh.positions.len() / 3) as u32;
            let v = c[0] as usize;
            mesh.positions.extend_from_slice(&positions[v * 3..v * 3 + 3]);
            if !texcoords.is_empty() && c[1] != MISSING {
                let t = c[1] as usize;
                mesh.texcoords.extend_from_slice(&texcoords[t * 2..t * 2 + 2]);
            }
            if !normals.is_empty() && c[2] != MISSING {
                let k = c[2] as usize;
                mesh.normals.extend_from_slice(&normals[k * 3..k * 3 + 3]);
            }
            if !colours.is_empty() {
                mesh.vertex_color.extend_from_slice(&colours[v * 3..v * 3 + 3]);
            }
        }
        mesh.indices.push(*slot);
    }
    if g.arities.iter().any(|&a| a != 3) {
        mesh.face_arities = g.arities;
    }
    tobj::Model::new(mesh, g.name)
}

#[cfg(test)]
mod tests {
    use super::super::text::{join_continuations, prepare_obj};
    use super::*;
    use proptest::prelude::*;
    use std::io::BufReader;

    /// The newline count in 8-bit lanes is the plain count, over blocks that end on a
    /// newline, runs of more than 255 newlines, and none.
    #[test]
    fn newlines_are_counted() {
        for text in [
            "",
            "v",
            "\n",
            "f 1 2 3\n",
            &"\n".repeat(1000),
            &"ab\ncd\n\n".repeat(300),
        ] {
            let want = text.bytes().filter(|&b| b == b'\n').count();
            assert_eq!(newlines(text.as_bytes()), want, "{:?}", &text[..text.len().min(20)]);
        }
    }

    /// The models, materials, notes and origin a reader gives.
    type Outcome = (Vec<tobj::Model>, Vec<tobj::Material>, Vec<String>, DVec3);

    const MTL: &str = "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n";

    /// The reader as first written: the text checked and rewritten, then parsed by tobj.
    fn reference(src: &str) -> Result<Outcome, String> {
        let src = join_continuations(src);
        let p = prepare_obj(Path::new("t.obj"), &src).map_err(|e| e.to_string())?;
        let opts = tobj::LoadOptions {
            triangulate: false,
            single_index: true,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, mats) = tobj::load_obj_buf(&mut BufReader::new(p.text.as_bytes()), &opts, |_| {
            tobj::load_mtl_buf(&mut BufReader::new(MTL.as_bytes()))
        })
        .map_err(|e| e.to_string())?;
        Ok((models, mats.unwrap_or_default(), p.notes, p.origin))
    }

    /// Our reader, the text cut into `chunks` runs read side by side.
    fn ours_in(src: &str, chunks: usize) -> Result<Outcome, String> {
        let src = join_continuations(src);
        let r = read_in_chunks(
            Path::new("t.obj"),
            &src,
            &mut |_| tobj::load_mtl_buf(&mut BufReader::new(MTL.as_bytes())),
            chunks,
        )
        .map_err(|e| e.to_string())?;
        Ok((r.models, r.materials.unwrap_or_default(), r.notes, r.origin))
    }

    /// An outcome as text, every float by its bits.
    fn shown(o: &Result<Outcome, String>) -> String {
        match o {
            Err(e) => format!("error {e}"),
            Ok((models, mats, notes, origin)) => {
                let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                let m: Vec<_> = models
                    .iter()
                    .map(|x| {
                        let m = &x.mesh;
                        let floats = [&m.positions, &m.normals, &m.texcoords, &m.vertex_color].map(|v| bits(v));
                        (&x.name, floats, &m.indices, &m.face_arities, m.material_id)
                    })
                    .collect();
                format!("{m:?} {} {notes:?} {origin:?}", mats.len())
            }
        }
    }

    fn same(src: &str) {
        let one = ours_in(src, 1);
        // The same models and notes, or the same first error, however the text is cut.
        for chunks in [2, 3, 7] {
            assert_eq!(shown(&one), shown(&ours_in(src, chunks)), "{chunks} chunks of\n{src}");
        }
        match (reference(src), one) {
            (Ok(a), Ok(b)) => {
                assert_eq!(a.0.len(), b.0.len(), "models of\n{src}");
                for (x, y) in a.0.iter().zip(&b.0) {
                    let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                    let (m, n) = (&x.mesh, &y.mesh);
                    assert_eq!(x.name, y.name, "{src}");
                    assert_eq!(bits(&m.positions), bits(&n.positions), "{src}");
                    assert_eq!(bits(&m.normals), bits(&n.normals), "{src}");
                    assert_eq!(bits(&m.texcoords), bits(&n.texcoords), "{src}");
                    assert_eq!(bits(&m.vertex_color), bits(&n.vertex_color), "{src}");
                    assert_eq!(m.indices, n.indices, "{src}");
                    assert_eq!(m.face_arities, n.face_arities, "{src}");
                    assert_eq!(m.material_id, n.material_id, "{src}");
                }
                assert_eq!(a.1.len(), b.1.len());
                assert_eq!(a.2, b.2, "notes of\n{src}");
                assert_eq!(a.3, b.3, "origin of\n{src}");
            }
            (Err(a), Err(b)) => {
                // Both refuse it; tobj's own errors named no line, ours do.
                if !a.contains("tobj does not say") {
                    assert_eq!(a, b, "{src}");
                }
            }
            (a, b) => panic!("{src}\nreference {:?}\nours {:?}", a.map(|_| ()), b.map(|_| ())),
        }
    }

    proptest! {
        /// The plain decimals' shortcut gives what `parse` gives, in f64 and f32, and leaves
        /// alone what it cannot read exactly.
        #[test]
        fn plain_decimals_read_as_parse_reads_them(
            sign in prop::sample::select(vec!["", "-", "+"]),
            int in "[0-9]{0,12}",
            frac in prop::option::of("[0-9]{0,12}"),
        ) {
            let word = format!("{sign}{int}{}", frac.map(|f| format!(".{f}")).unwrap_or_default());
            match plain_decimal(&word) {
                Some((x, f)) => {
                    prop_assert_eq!(x.to_bits(), word.parse::<f64>().unwrap().to_bits(), "{}", word);
                    prop_assert_eq!(f.to_bits(), word.parse::<f32>().unwrap().to_bits(), "{}", word);
                }
                None => prop_assert!(word.parse::<f64>().is_err() || word.trim_start_matches(['-', '+']).len() > 15),
            }
        }

        /// The vertex statements' shortcut (for the counts before each chunk) finds the first
        /// word `words` finds, or asks it.
        #[test]
        fn vertex_kinds_as_words_finds_them(line in "[vtn1 #\t\r\u{b}é\u{a0}\u{3000}x]{0,8}") {
            let mut w = Vec::new();
            words(&line, &mut w);
            let want = w.first().and_then(|&(_, kw)| ["v", "vt", "vn"].iter().position(|&v| v == kw));
            if let Some(kind) = vertex_kind(&line) {
                prop_assert_eq!(kind, want, "{:?}", line);
            }
        }

        /// Decimals of up to 19 digits, the f32 by way of the f64 where its fast path does
        /// not hold, as `parse` reads them.
        #[test]
        fn long_plain_decimals_read_as_parse_reads_them(m in 0u64..(1 << 53), point in 0usize..20, negative in any::<bool>()) {
            let digits = m.to_string();
            let point = point.min(digits.len());
            let word = format!("{}{}.{}", if negative { "-" } else { "" }, &digits[..digits.len() - point], &digits[digits.len() - point..]);
            if let Some((x, f)) = plain_decimal(&word) {
                prop_assert_eq!(x.to_bits(), word.parse::<f64>().unwrap().to_bits(), "{}", word);
                prop_assert_eq!(f.to_bits(), word.parse::<f32>().unwrap().to_bits(), "{}", word);
            }
        }

        /// The plain indices' shortcut gives what `parse` gives.
        #[test]
        fn plain_indices_read_as_parse_reads_them(word in "-?[0-9]{1,20}") {
            if let Some(v) = plain_index(&word) {
                prop_assert_eq!(Some(v), word.parse::<i64>().ok());
            }
        }
    }

    /// Decimals exactly halfway between two f32 (2^24 + 1 and its like): to even, as `parse`
    /// reads them.
    #[test]
    fn halfway_decimals_read_as_parse_reads_them() {
        for word in [
            "16777217",
            "16777219",
            "-33554434",
            "1677721.7",
            "0.16777217",
            "8388608.5",
            "100000001",
        ] {
            let (x, f) = plain_decimal(word).expect(word);
            assert_eq!(x.to_bits(), word.parse::<f64>().unwrap().to_bits(), "{word}");
            assert_eq!(f.to_bits(), word.parse::<f32>().unwrap().to_bits(), "{word}");
        }
    }

    /// Decimals that the f64 rounds onto a point halfway between two f32 (16 digits near 8 + an
    /// odd multiple of 2^-21): rounding that f64 to f32 would round some of them the wrong way
    /// (the test finds such cases), the reader rounds them as `parse` does.
    #[test]
    fn decimals_rounded_onto_halfway_points_read_as_parse_reads_them() {
        let (mut hazards, mut wrong_by_f64) = (0, 0);
        for k in 0..20_000u32 {
            let halfway = 8.0 + f64::from(2 * k + 1) * (-21f64).exp2();
            // 15 decimals: within half the f64's last place of the halfway point, not on it.
            let word = format!("{halfway:.15}");
            let x = word.parse::<f64>().unwrap();
            if x != halfway {
                continue;
            }
            let exact = word.parse::<f32>().unwrap();
            hazards += 1;
            wrong_by_f64 += usize::from((x as f32).to_bits() != exact.to_bits());
            let (ours_x, ours) = plain_decimal(&word).expect("a plain decimal of 16 digits");
            assert_eq!(ours_x.to_bits(), x.to_bits(), "{word}");
            assert_eq!(ours.to_bits(), exact.to_bits(), "{word}");
        }
        assert!(
            hazards > 100 && wrong_by_f64 > 0,
            "{hazards} cases, {wrong_by_f64} that the f64 alone rounds wrong"
        );
    }

    fn number() -> impl Strategy<Value = String> {
        prop_oneof![
            (-50i32..50).prop_map(|i| i.to_string()),
            (-5.0f64..5.0).prop_map(|x| format!("{x}")),
            (-5.0f32..5.0).prop_map(|x| format!("{x:e}")),
            Just("1e39".to_string()),
            Just("1.5x".to_string()),
            Just(".5".to_string()),
            Just("3.1+e2".to_string()),
            Just("123456789.123".to_string()),
            Just("1e12".to_string()),
        ]
    }

    fn statement() -> impl Strategy<Value = String> {
        let idx = prop_oneof![
            4 => (1i32..5).prop_map(|i| i.to_string()),
            1 => (1i32..12).prop_map(|i| i.to_string()),
            1 => (-4i32..0).prop_map(|i| i.to_string())
        ];
        let corner =
            (idx.clone(), prop::option::of(idx.clone()), prop::option::of(idx)).prop_map(|(v, t, n)| match (t, n) {
                (None, None) => v,
                (Some(t), None) => format!("{v}/{t}"),
                (None, Some(n)) => format!("{v}//{n}"),
                (Some(t), Some(n)) => format!("{v}/{t}/{n}"),
            });
        prop_oneof![
            6 => prop::collection::vec(number(), 3..4).prop_map(|n| format!("v {}", n.join(" "))),
            1 => prop::collection::vec(number(), 4..8).prop_map(|n| format!("v {}", n.join(" "))),
            2 => prop::collection::vec(number(), 1..4).prop_map(|n| format!("vt {}", n.join(" "))),
            2 => prop::collection::vec(number(), 3..4).prop_map(|n| format!("vn {}", n.join(" "))),
            6 => prop::collection::vec(corner, 1..6).prop_map(|c| format!("f {}", c.join(" "))),
            1 => prop_oneof![Just("o a"), Just("g b # c"), Just("  g  lead"), Just("g"), Just("o")].prop_map(String::from),
            1 => prop_oneof![Just("usemtl red"), Just("usemtl green"), Just("usemtl nothing"), Just("usemtl"), Just("  usemtl red")].prop_map(String::from),
            1 => prop_oneof![Just("mtllib t.mtl"), Just("l 1 2"), Just("p 1"), Just("s 1"), Just("# x"), Just(""), Just("v 1 2 \\")].prop_map(String::from),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(600))]
        /// The one-pass reader gives what the rewrite and tobj gave: the same models, vertices
        /// (bit for bit), materials, notes and origin, or both refuse the file.
        #[test]
        fn reads_as_the_rewrite_and_tobj_did(lines in prop::collection::vec(statement(), 0..40), far in any::<bool>()) {
            let mut src = String::new();
            if far {
                src.push_str("v 1000000 2000000 3000000\n");
            }
            src.push_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n");
            for l in &lines {
                src.push_str(l);
                src.push('\n');
            }
            same(&src);
        }
    }

    /// The real files beside the project, read both ways.
    #[test]
    fn real_models_read_alike() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
        let mut stack = vec![root];
        let mut n = 0;
        while let Some(d) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&d) else { continue };
            for e in entries.flatten() {
                let p = e.path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("obj")) {
                    let text = String::from_utf8_lossy(&std::fs::read(&p).unwrap()).into_owned();
                    same(&text);
                    n += 1;
                }
            }
        }
        eprintln!("{n} OBJ files compared");
    }
}
