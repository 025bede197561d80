//! Stanford PLY, ASCII and binary (either byte order), read in one pass over the file's bytes:
//! the `vertex` element's positions, normals and colours straight into arrays, the `face`
//! element's index lists into triangles; other elements are read past. Every count a header
//! claims is held to what the rest of the file can hold before anything is allocated, and every
//! error names the header line, or the element and row (and, in an ASCII file, the line).

use super::ModelPart;
use super::{far_origin, model_error, part_name, polygon, recentred, vertex_color_material};
use crate::Error;
use glam::{DVec3, Vec3};
use phong_core::{Color, Mesh};
use std::path::Path;

/// A scalar type of PLY (and its other names).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn named(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The value at the start of `b` (at least `size` bytes), big-endian where `big`.
    #[inline]
    fn get(self, b: &[u8], big: bool) -> f64 {
        macro_rules! num {
            ($t:ty, $n:expr) => {{
                let a: [u8; $n] = b[..$n].try_into().expect("length checked");
                f64::from(if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                })
            }};
        }
        match self {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => num!(i16, 2),
            Scalar::U16 => num!(u16, 2),
            Scalar::I32 => num!(i32, 4),
            Scalar::U32 => num!(u32, 4),
            Scalar::F32 => num!(f32, 4),
            Scalar::F64 => {
                let a: [u8; 8] = b[..8].try_into().expect("length checked");
                if big {
                    f64::from_be_bytes(a)
                } else {
                    f64::from_le_bytes(a)
                }
            }
        }
    }

    /// A colour channel in [0, 1] of this type: integers of 8 bits over 255 (signed: 127), of
    /// 16 over 65535, floats as they are (clamped); other types have none.
    fn channel(self, v: f64) -> Option<f64> {
        let v = match self {
            Scalar::U8 => v / 255.0,
            Scalar::I8 => v / 127.0,
            Scalar::U16 => v / 65535.0,
            Scalar::F32 | Scalar::F64 => v,
            _ => return None,
        };
        v.is_finite().then(|| v.clamp(0.0, 1.0))
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Scalar(Scalar),
    /// A list: its count's type and its items'.
    List(Scalar, Scalar),
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// The header: the body's format and elements, and where the body begins.
struct Header {
    format: Format,
    elements: Vec<Element>,
    body: usize,
}

/// The header of a PLY file (`bytes` begin with `ply`), or a message naming its line.
fn header(bytes: &[u8]) -> Result<Header, String> {
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut at = 0;
    let mut n = 0;
    loop {
        let Some(len) = bytes[at..].iter().position(|&b| b == b'\n') else {
            return Err("the header has no `end_header` line".into());
        };
        n += 1;
        let line = String::from_utf8_lossy(&bytes[at..at + len]);
        at += len + 1;
        let here = |m: String| format!("header line {n}: {m}");
        // A number of more digits than u64 holds, wherever it is (before the line is read).
        for run in line.split(|c: char| !c.is_ascii_digit()).filter(|r| !r.is_empty()) {
            if run.parse::<u64>().is_err() {
                return Err(here(format!("the number {run} is too large")));
            }
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] => {}
            ["ply"] if n == 1 => {}
            _ if n == 1 => return Err(here("a PLY file begins with the line `ply`".into())),
            ["end_header"] => break,
            ["comment" | "obj_info", ..] => {}
            ["format", f, _version] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    other => return Err(here(format!("unknown format `{other}`"))),
                })
            }
            ["element", name, count] => {
                let count = count
                    .parse()
                    .map_err(|_| here(format!("`{count}` is not an element count")))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            ["property", rest @ ..] => {
                let type_of = |t: &str| Scalar::named(t).ok_or_else(|| here(format!("unknown type `{t}`")));
                let (kind, name) = match rest {
                    ["list", count, item, name] => (Kind::List(type_of(count)?, type_of(item)?), name),
                    [t, name] => (Kind::Scalar(type_of(t)?), name),
                    _ => return Err(here(format!("`{}` is not a property line", line.trim()))),
                };
                if let Kind::List(c, _) = kind
                    && !c.is_integer()
                {
                    return Err(here("a list's count must be of an integer type".into()));
                }
                let Some(e) = elements.last_mut() else {
                    return Err(here("a property before any `element`".into()));
                };
                e.props.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            _ => return Err(here(format!("`{}` is not a header line", line.trim()))),
        }
    }
    let format = format.ok_or("the header has no `format` line")?;
    Ok(Header {
        format,
        elements,
        body: at,
    })
}

/// Where the wanted vertex properties are in a row (their index in the element's properties).
#[derive(Default)]
struct VertexSlots {
    p: [Option<usize>; 3],
    n: [Option<usize>; 3],
    c: [Option<usize>; 3],
}

impl VertexSlots {
    fn of(e: &Element) -> VertexSlots {
        let mut s = VertexSlots::default();
        for (i, p) in e.props.iter().enumerate() {
            if !matches!(p.kind, Kind::Scalar(_)) {
                continue;
            }
            let slot = match p.name.as_str() {
                "x" => &mut s.p[0],
                "y" => &mut s.p[1],
                "z" => &mut s.p[2],
                "nx" => &mut s.n[0],
                "ny" => &mut s.n[1],
                "nz" => &mut s.n[2],
                "red" | "r" | "diffuse_red" => &mut s.c[0],
                "green" | "g" | "diffuse_green" => &mut s.c[1],
                "blue" | "b" | "diffuse_blue" => &mut s.c[2],
                _ => continue,
            };
            *slot = Some(i);
        }
        s
    }
}

/// What the body gives: per vertex its position, normal (where the element has all three) and
/// colour (where every vertex has one); per face its indices, as given.
#[derive(Default)]
struct Body {
    points: Vec<DVec3>,
    normals: Option<Vec<Vec3>>,
    colors: Option<Vec<Color>>,
    /// The faces' indices, one after another; `starts[k]..starts[k + 1]` is face k's.
    indices: Vec<i64>,
    starts: Vec<usize>,
    /// A face element without an index list (its first face, for the message).
    faces_without_indices: bool,
}

/// The values of one row, read from whichever encoding.
trait Rows {
    /// The next scalar of type `t`.
    fn scalar(&mut self, t: Scalar) -> Result<f64, String>;
    /// Where the reader is, for a message ("line 12" in an ASCII file).
    fn place(&self) -> String;
    /// A binary body's bytes, the reader's offset in them and whether they are big-endian,
    /// for elements read whole; `None` for ASCII.
    fn raw(&mut self) -> Option<(&[u8], &mut usize, bool)> {
        None
    }
}

struct Binary<'a> {
    bytes: &'a [u8],
    at: usize,
    big: bool,
}

impl Rows for Binary<'_> {
    #[inline]
    fn scalar(&mut self, t: Scalar) -> Result<f64, String> {
        let end = self.at + t.size();
        let b = self.bytes.get(self.at..end).ok_or("the file ends inside it")?;
        self.at = end;
        Ok(t.get(b, self.big))
    }
    fn place(&self) -> String {
        format!("byte {}", self.at)
    }
    fn raw(&mut self) -> Option<(&[u8], &mut usize, bool)> {
        Some((self.bytes, &mut self.at, self.big))
    }
}

struct Ascii<'a> {
    bytes: &'a [u8],
    at: usize,
    line: usize,
}

impl Rows for Ascii<'_> {
    fn scalar(&mut self, t: Scalar) -> Result<f64, String> {
        while let Some(&b) = self.bytes.get(self.at) {
            if !b.is_ascii_whitespace() {
                break;
            }
            self.line += usize::from(b == b'\n');
            self.at += 1;
        }
        let start = self.at;
        while self.bytes.get(self.at).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.at += 1;
        }
        if start == self.at {
            return Err("the file ends inside it".into());
        }
        let word = std::str::from_utf8(&self.bytes[start..self.at]).unwrap_or("?");
        let v = if t.is_integer() {
            word.parse::<i64>().map(|v| v as f64).ok()
        } else {
            word.parse::<f64>().ok().filter(|v| v.is_finite())
        };
        v.ok_or_else(|| {
            let what = if t.is_integer() {
                "an integer"
            } else {
                "a finite number"
            };
            format!("`{word}` is not {what}")
        })
    }
    fn place(&self) -> String {
        format!("line {}", self.line)
    }
}

/// Reads every element of the body from `rows`, keeping the vertices' and faces'.
fn read_body<R: Rows>(h: &Header, rows: &mut R, room: usize) -> Result<Body, String> {
    let mut body = Body::default();
    for e in &h.elements {
        // Each row of an element with properties takes a byte at least (two in ASCII).
        let min_row = match h.format {
            Format::Ascii => 2 * e.props.len(),
            _ => e
                .props
                .iter()
                .map(|p| match p.kind {
                    Kind::Scalar(t) => t.size(),
                    Kind::List(c, _) => c.size(),
                })
                .sum(),
        };
        if !e.props.is_empty() && e.count.saturating_mul(min_row as u64) > room as u64 {
            return Err(format!(
                "element {} claims {} rows, more than the file's {room} bytes hold",
                e.name, e.count
            ));
        }
        let at = |row: u64, place: String, m: String| format!("element {} row {row} ({place}): {m}", e.name);
        match e.name.as_str() {
            "vertex" => read_vertices(e, rows, &mut body).map_err(|(row, m)| at(row, rows.place(), m))?,
            "face" => read_faces(e, rows, &mut body).map_err(|(row, m)| at(row, rows.place(), m))?,
            _ if e.props.is_empty() => {}
            _ => {
                for row in 0..e.count {
                    for p in &e.props {
                        read_property(p.kind, rows, |_| {}).map_err(|m| at(row, rows.place(), m))?;
                    }
                }
            }
        }
    }
    Ok(body)
}

/// One property's value(s), each given to `item` (a list's items, or the scalar).
#[inline]
fn read_property<R: Rows>(kind: Kind, rows: &mut R, mut item: impl FnMut(f64)) -> Result<(), String> {
    match kind {
        Kind::Scalar(t) => item(rows.scalar(t)?),
        Kind::List(c, t) => {
            let n = rows.scalar(c)?;
            if !(0.0..=1e9).contains(&n) {
                return Err(format!("a list of {n} items"));
            }
            for _ in 0..n as usize {
                item(rows.scalar(t)?);
            }
        }
    }
    Ok(())
}

fn read_vertices<R: Rows>(e: &Element, rows: &mut R, body: &mut Body) -> Result<(), (u64, String)> {
    let s = VertexSlots::of(e);
    let n = e.count as usize;
    let has = |slots: &[Option<usize>; 3]| slots.iter().all(Option::is_some);
    let (want_n, want_c) = (has(&s.n), has(&s.c));
    let types: Vec<Kind> = e.props.iter().map(|p| p.kind).collect();
    let channel_type = |i: Option<usize>| match i.map(|i| types[i]) {
        Some(Kind::Scalar(t)) => t,
        _ => Scalar::I32,
    };
    let ct = s.c.map(channel_type);
    if e.count > 0 && !has(&s.p) {
        return Err((0, "vertex 0 has no x, y and z".into()));
    }
    body.points.reserve_exact(n);
    if !want_n && !want_c && binary_positions(e, &s, rows, body) {
        return Ok(());
    }
    let mut normals = Vec::with_capacity(if want_n { n } else { 0 });
    let mut colors = Vec::with_capacity(if want_c { n } else { 0 });
    let mut all_colored = want_c;
    let mut v = vec![0.0f64; types.len()];
    for row in 0..e.count {
        for (k, kind) in types.iter().enumerate() {
            let mut last = 0.0;
            read_property(*kind, rows, |x| last = x).map_err(|m| (row, m))?;
            v[k] = last;
        }
        let get = |i: Option<usize>| i.map(|i| v[i]);
        let [Some(x), Some(y), Some(z)] = s.p.map(get) else {
            return Err((row, format!("vertex {row} has no x, y and z")));
        };
        body.points.push(DVec3::new(x, y, z));
        if want_n {
            let [x, y, z] = s.n.map(|i| get(i).unwrap_or(0.0) as f32);
            normals.push(Vec3::new(x, y, z).normalize_or_zero());
        }
        if all_colored {
            let c = [0, 1, 2].map(|k| ct[k].channel(get(s.c[k]).unwrap_or(0.0)));
            match c {
                [Some(r), Some(g), Some(b)] => colors.push(Color::new(r as f32, g as f32, b as f32)),
                _ => all_colored = false,
            }
        }
    }
    body.normals = want_n.then_some(normals);
    body.colors = all_colored.then_some(colors);
    Ok(())
}

fn read_faces<R: Rows>(e: &Element, rows: &mut R, body: &mut Body) -> Result<(), (u64, String)> {
    let list = e
        .props
        .iter()
        .position(|p| matches!(p.kind, Kind::List(..)) && (p.name == "vertex_indices" || p.name == "vertex_index"));
    if list.is_none() && e.count > 0 {
        body.faces_without_indices = true;
        return Ok(());
    }
    body.starts.reserve_exact(e.count as usize + 1);
    body.indices.reserve(3 * e.count as usize);
    body.starts.push(body.indices.len());
    if e.props.len() == 1 && binary_lists(e, rows, body) {
        return Ok(());
    }
    let indices = &mut body.indices;
    for row in 0..e.count {
        for (k, p) in e.props.iter().enumerate() {
            if Some(k) == list {
                read_property(p.kind, rows, |i| indices.push(i as i64)).map_err(|m| (row, m))?;
            } else {
                read_property(p.kind, rows, |_| {}).map_err(|m| (row, m))?;
            }
        }
        body.starts.push(indices.len());
    }
    Ok(())
}

/// A binary body's vertices of scalar properties read whole, their positions only, in rows of
/// fixed size; false (nothing read) where they are not such rows or the file ends inside them
/// (the general reader then says where).
fn binary_positions<R: Rows>(e: &Element, s: &VertexSlots, rows: &mut R, body: &mut Body) -> bool {
    let Some((bytes, at, big)) = rows.raw() else {
        return false;
    };
    let Some(types) = e
        .props
        .iter()
        .map(|p| match p.kind {
            Kind::Scalar(t) => Some(t),
            Kind::List(..) => None,
        })
        .collect::<Option<Vec<Scalar>>>()
    else {
        return false;
    };
    let mut offsets = Vec::with_capacity(types.len());
    let mut stride = 0;
    for t in &types {
        offsets.push(stride);
        stride += t.size();
    }
    let Some(need) = usize::try_from(e.count).ok().and_then(|n| n.checked_mul(stride)) else {
        return false;
    };
    let [Some(x), Some(y), Some(z)] = s.p else {
        return e.count == 0;
    };
    if stride == 0 || bytes.len() - *at < need {
        return false;
    }
    let [(ox, tx), (oy, ty), (oz, tz)] = [x, y, z].map(|i| (offsets[i], types[i]));
    let rows_of = bytes[*at..*at + need].chunks_exact(stride);
    if [tx, ty, tz] == [Scalar::F32; 3] {
        // The common layout (float x, y, z): no dispatch on the type per value.
        let f = |row: &[u8], o: usize| {
            let a: [u8; 4] = row[o..o + 4].try_into().expect("inside the row");
            f64::from(if big {
                f32::from_be_bytes(a)
            } else {
                f32::from_le_bytes(a)
            })
        };
        body.points
            .extend(rows_of.map(|row| DVec3::new(f(row, ox), f(row, oy), f(row, oz))));
        *at += need;
        return true;
    }
    for row in rows_of {
        body.points.push(DVec3::new(
            tx.get(&row[ox..], big),
            ty.get(&row[oy..], big),
            tz.get(&row[oz..], big),
        ));
    }
    *at += need;
    true
}

/// A binary body's faces that are one list each, read whole; false (nothing kept) where the
/// file ends inside them or a list's count is out of range (the general reader then says
/// where).
fn binary_lists<R: Rows>(e: &Element, rows: &mut R, body: &mut Body) -> bool {
    let Kind::List(c, t) = e.props[0].kind else {
        return false;
    };
    let Some((bytes, at, big)) = rows.raw() else {
        return false;
    };
    let (indices, starts) = (body.indices.len(), body.starts.len());
    let (cs, ts) = (c.size(), t.size());
    let mut p = *at;
    if c == Scalar::U8 && matches!(t, Scalar::I32 | Scalar::U32) {
        p = int_triangles(bytes, p, e.count, t == Scalar::I32, big, body);
    }
    for _ in body.starts.len() - starts..e.count as usize {
        let Some(k) = bytes
            .get(p..p + cs)
            .map(|b| c.get(b, big))
            .filter(|k| (0.0..=1e9).contains(k))
        else {
            break;
        };
        let end = p + cs + k as usize * ts;
        let Some(items) = bytes.get(p + cs..end) else {
            break;
        };
        body.indices
            .extend(items.chunks_exact(ts).map(|i| t.get(i, big) as i64));
        body.starts.push(body.indices.len());
        p = end;
    }
    if body.starts.len() - starts == e.count as usize {
        *at = p;
        return true;
    }
    body.indices.truncate(indices);
    body.starts.truncate(starts);
    false
}

/// The faces from `bytes[p..]` that are triangles of 32-bit indices after a `uchar` count (as
/// most writers write them), up to `count` faces in all or the first other face; returns where
/// it stopped (the caller reads the rest).
fn int_triangles(bytes: &[u8], mut p: usize, count: u64, signed: bool, big: bool, body: &mut Body) -> usize {
    let index = |b: &[u8]| {
        let a: [u8; 4] = b.try_into().expect("4 bytes");
        let u = if big {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        };
        // A signed index below zero stays negative, to be refused with its value.
        if signed { i64::from(u as i32) } else { i64::from(u) }
    };
    let mut left = count;
    while left > 0 {
        let Some(face) = bytes.get(p..p + 13).filter(|f| f[0] == 3) else {
            break;
        };
        body.indices
            .extend([index(&face[1..5]), index(&face[5..9]), index(&face[9..13])]);
        body.starts.push(body.indices.len());
        p += 13;
        left -= 1;
    }
    p
}

/// A PLY file's `vertex` and `face` elements as one part (polygons triangulated; other
/// elements read past).
pub(crate) fn read_ply(path: &Path, bytes: &[u8]) -> Result<Vec<ModelPart>, Error> {
    let fail = |m: String| model_error(path, format!("malformed PLY: {m}"));
    let h = header(bytes).map_err(fail)?;
    let (positions, origin, triangles, normals, colors) = match plain_binary(&h, bytes) {
        Some((positions, triangles)) => {
            let origin = far_origin(positions.iter().map(|p| p.as_dvec3()));
            let positions = if origin == DVec3::ZERO {
                positions
            } else {
                positions.iter().map(|p| (p.as_dvec3() - origin).as_vec3()).collect()
            };
            (positions, origin, triangles, None, None)
        }
        None => general(&h, bytes).map_err(fail)?,
    };
    if triangles.is_empty() {
        return Err(model_error(
            path,
            format!(
                "no faces: a point cloud of {} points, nothing to render",
                positions.len()
            ),
        ));
    }
    let has_normals = normals.is_some() && !positions.is_empty();
    let normals = normals.unwrap_or_else(|| vec![Vec3::ZERO; positions.len()]);
    let mesh = Mesh::new(positions, normals, triangles)
        .and_then(|m| m.with_colors(colors.unwrap_or_default()))
        .map_err(|e| fail(e.to_string()))?;
    // With colours, a white material: they are the ambient and diffuse colours.
    let material = (!mesh.colors().is_empty()).then(vertex_color_material);
    Ok(vec![ModelPart {
        name: part_name(path),
        mesh,
        material,
        maps: phong_core::Maps::default(),
        has_normals,
        flat_without_normals: false,
        origin,
        drawn: None,
        fitted: None,
    }])
}

/// The body of any PLY file read by the general reader (every format, type and layout; errors
/// name the element and row): positions re-centred, their origin, the faces triangulated, and
/// the normals and colours where the vertices have them.
#[allow(clippy::type_complexity)]
fn general(
    h: &Header,
    bytes: &[u8],
) -> Result<(Vec<Vec3>, DVec3, Vec<[u32; 3]>, Option<Vec<Vec3>>, Option<Vec<Color>>), String> {
    let room = bytes.len() - h.body;
    let body = match h.format {
        Format::Ascii => {
            let line = 1 + bytes[..h.body].iter().filter(|&&b| b == b'\n').count();
            let mut rows = Ascii {
                bytes,
                at: h.body,
                line,
            };
            read_body(h, &mut rows, room)
        }
        f => {
            let mut rows = Binary {
                bytes,
                at: h.body,
                big: f == Format::Big,
            };
            read_body(h, &mut rows, room)
        }
    }?;
    if body.faces_without_indices {
        return Err("face 0 has no vertex_indices".into());
    }
    for (i, p) in body.points.iter().enumerate() {
        if !p.as_vec3().is_finite() {
            return Err(format!("vertex {i} is not finite in f32: {p}"));
        }
    }
    let (positions, origin) = recentred(&body.points);
    let n = positions.len() as i64;
    let mut triangles = Vec::with_capacity(body.indices.len() / 3);
    let mut corners = Vec::new();
    for (k, w) in body.starts.windows(2).enumerate() {
        let idx = &body.indices[w[0]..w[1]];
        if let Some(bad) = idx.iter().find(|&&i| i < 0 || i >= n) {
            return Err(format!("face {k}: vertex index {bad} is out of range ({n} vertices)"));
        }
        if let [a, b, c] = *idx {
            triangles.push([a as u32, b as u32, c as u32]);
            continue;
        }
        corners.clear();
        corners.extend(idx.iter().map(|&i| positions[i as usize]));
        triangles.extend(
            polygon::triangulate(&corners)
                .into_iter()
                .map(|t| t.map(|k| idx[k as usize] as u32)),
        );
    }
    Ok((positions, origin, triangles, body.normals, body.colors))
}

/// The common binary file (trimesh's, Open3D's, most scanners'): a `vertex` element of scalar
/// properties with `float` x, y and z and no normals or colours, then a `face` element of one
/// list of triangles (`uchar` count, `int` or `uint` indices), nothing after. Its positions and
/// triangles read in one pass each, without the general reader's per-value dispatch; `None`
/// (nothing read) for any other file or anything amiss (a non-finite position, an index out of
/// range, a face not a triangle, the file too short), which the general reader then reads or
/// refuses with its message.
fn plain_binary(h: &Header, bytes: &[u8]) -> Option<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let big = match h.format {
        Format::Ascii => return None,
        f => f == Format::Big,
    };
    let [v, f] = &h.elements[..] else {
        return None;
    };
    if v.name != "vertex" || f.name != "face" {
        return None;
    }
    let s = VertexSlots::of(v);
    if s.n.iter().all(Option::is_some) || s.c.iter().all(Option::is_some) {
        return None;
    }
    let mut stride = 0;
    let mut offsets = [0usize; 3];
    for (i, p) in v.props.iter().enumerate() {
        let Kind::Scalar(t) = p.kind else {
            return None;
        };
        if let Some(k) = s.p.iter().position(|&slot| slot == Some(i)) {
            if t != Scalar::F32 {
                return None;
            }
            offsets[k] = stride;
        }
        stride += t.size();
    }
    if s.p.iter().any(Option::is_none) {
        return None;
    }
    let [face] = &f.props[..] else {
        return None;
    };
    let (Kind::List(Scalar::U8, Scalar::I32 | Scalar::U32), "vertex_indices" | "vertex_index") =
        (face.kind, face.name.as_str())
    else {
        return None;
    };
    let (n, faces) = (usize::try_from(v.count).ok()?, usize::try_from(f.count).ok()?);
    let vertex_bytes = n.checked_mul(stride)?;
    let face_bytes = faces.checked_mul(13)?;
    let body = bytes.get(h.body..)?;
    // (At most 2^31 vertices: an `int` index below zero, read as a `uint`, is then past all.)
    if body.len() != vertex_bytes.checked_add(face_bytes)? || n > i32::MAX as usize {
        return None;
    }
    let word = |b: &[u8], o: usize| {
        let a: [u8; 4] = b[o..o + 4].try_into().expect("4 bytes");
        if big {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        }
    };
    let positions: Vec<Vec3> = if !big && cfg!(target_endian = "little") && stride == 12 && offsets == [0, 4, 8] {
        // Little-endian x, y, z alone on a little-endian machine: the bytes are the vertex
        // array (a copy, as the file's bytes need not be aligned).
        bytemuck::pod_collect_to_vec(&body[..vertex_bytes])
    } else {
        body[..vertex_bytes]
            .chunks_exact(stride)
            .map(|row| Vec3::from_array(offsets.map(|o| f32::from_bits(word(row, o)))))
            .collect()
    };
    if !positions.iter().all(|p| p.is_finite()) {
        return None;
    }
    let (triangles, counts_ok, largest) = if big {
        triangle_rows::<true>(&body[vertex_bytes..])
    } else {
        triangle_rows::<false>(&body[vertex_bytes..])
    };
    (counts_ok && (triangles.is_empty() || (largest as usize) < n)).then_some((positions, triangles))
}

/// The triangles of rows of 13 bytes (a count, then three 32-bit indices, big-endian where
/// `BIG`), whether every count is 3, and the largest index: every row checked without a
/// branch, its bytes read from a fixed-size array (no bounds check).
fn triangle_rows<const BIG: bool>(rows: &[u8]) -> (Vec<[u32; 3]>, bool, u32) {
    let (mut counts_ok, mut largest) = (true, 0u32);
    let triangles = rows
        .as_chunks::<13>()
        .0
        .iter()
        .map(|row| {
            let word = |o: usize| {
                let b = [row[o], row[o + 1], row[o + 2], row[o + 3]];
                if BIG {
                    u32::from_be_bytes(b)
                } else {
                    u32::from_le_bytes(b)
                }
            };
            let tri = [word(1), word(5), word(9)];
            counts_ok &= row[0] == 3;
            largest = largest.max(tri[0]).max(tri[1]).max(tri[2]);
            tri
        })
        .collect();
    (triangles, counts_ok, largest)
}
