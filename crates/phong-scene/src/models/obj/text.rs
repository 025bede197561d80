//! What the OBJ reader shares: lines, continuation lines, words, numbers as `strtod` reads
//! them and plain decimals and indices without it, located errors; and, for the tests, the reader as first written (the text checked and
//! rewritten line for line for tobj to parse), which `read.rs` must agree with.

use crate::Error;
#[cfg(test)]
use glam::DVec3;
use std::path::Path;

/// Offset of the `n`th whitespace-separated field of `line` (0 = keyword), for columns.
pub(super) fn field_offset(line: &str, n: usize) -> usize {
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

pub(super) struct Checker<'a> {
    pub path: &'a Path,
    pub src: &'a str,
}

impl Checker<'_> {
    pub fn err(&self, line_start: usize, line: &str, field: usize, key: &str, msg: String) -> Error {
        Error::at(
            self.path,
            self.src,
            line_start + field_offset(line, field),
            Some(key),
            msg,
        )
    }
}

/// The material name an unnamed `usemtl` is read as: no library defines it, so the faces after
/// it take the default material.
pub(super) const NO_MATERIAL: &str = "phong:no-material";

/// `src` with each line that ends in `\` joined to the next (the format allows it; Rhino
/// writes it), the newlines it removes added after the joined line, so that every later line
/// keeps its number.
pub(super) fn join_continuations(src: &str) -> std::borrow::Cow<'_, str> {
    if memchr::memmem::find(src.as_bytes(), b"\\\n").is_none()
        && memchr::memmem::find(src.as_bytes(), b"\\\r\n").is_none()
    {
        return std::borrow::Cow::Borrowed(src);
    }
    let mut out = String::with_capacity(src.len());
    let mut pending = 0usize;
    let mut rest = src;
    while let Some(i) = rest.find('\n') {
        let (line, next) = (&rest[..i], &rest[i + 1..]);
        let body = line.strip_suffix('\r').unwrap_or(line);
        match body.strip_suffix('\\') {
            Some(head) => {
                out.push_str(head);
                out.push(' ');
                pending += 1;
            }
            None => {
                out.push_str(line);
                out.push('\n');
                out.extend(std::iter::repeat_n('\n', pending));
                pending = 0;
            }
        }
        rest = next;
    }
    out.push_str(rest);
    out.extend(std::iter::repeat_n('\n', pending));
    std::borrow::Cow::Owned(out)
}

pub(super) fn lines(src: &str) -> impl Iterator<Item = (usize, &str)> {
    // One searcher over the text (a search per line set itself up per line), and the last
    // line where the text does not end in a newline.
    let mut ends = memchr::memchr_iter(b'\n', src.as_bytes()).map(|i| i + 1);
    let mut off = 0;
    std::iter::from_fn(move || {
        if off >= src.len() {
            return None;
        }
        let start = off;
        off = ends.next().unwrap_or(src.len());
        Some((start, src[start..off].trim_end_matches(['\n', '\r'])))
    })
}

/// A number as C's `strtod` reads it, which is how other loaders read OBJ numbers: Rust's
/// grammar (`1.e-3`, `.8e-001`, `1e+02`), else the longest prefix that is a decimal number
/// (`3.1+e2` is 3.1). The second value is true when characters were left over.
pub(super) fn strtod(s: &str) -> Option<(f64, bool)> {
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

/// The whitespace-separated words of a statement (before any `#`), with their offsets in
/// `line`, into `out`.
pub(super) fn words<'a>(line: &'a str, out: &mut Vec<(usize, &'a str)>) {
    out.clear();
    if line.is_ascii() {
        // ASCII whitespace as `char::is_whitespace` has it: tab to carriage return, and space;
        // a `#` ends the statement.
        let white = |c: u8| matches!(c, b'\t'..=b'\r' | b' ');
        let b = line.as_bytes();
        let mut i = 0;
        while i < b.len() && b[i] != b'#' {
            while i < b.len() && white(b[i]) {
                i += 1;
            }
            let s = i;
            while i < b.len() && !white(b[i]) && b[i] != b'#' {
                i += 1;
            }
            if i > s {
                out.push((s, &line[s..i]));
            }
        }
        return;
    }
    let content = line.split('#').next().unwrap_or("");
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
}

/// A word that is a plain decimal (`-0.0378297`: a sign, at most 19 digits with at most one
/// point, no exponent) as `(f64, f32)`, each the correctly rounded value of its digits, as
/// `parse` gives them; `None` for anything else (or where the f64 is not exact by this
/// route). The mantissa and the power of ten are both exact in the float (at most 2^53 and
/// 10^22 for f64, 2^24 and 10^10 for f32), so one division rounds correctly (Clinger's fast
/// path); the f32 is parsed apart where its fast path does not hold.
pub(super) fn plain_decimal(word: &str) -> Option<(f64, f32)> {
    plain_decimal_at(word.as_bytes(), 0).and_then(|(x, f, end)| (end == word.len()).then_some((x, f)))
}

/// [`plain_decimal`] of the number that starts at `b[start]` (a sign, digits, a point,
/// digits), read up to the first byte that is none of these: its value and that byte's
/// index, read in the same pass as the line (no word split first).
pub(super) fn plain_decimal_at(b: &[u8], start: usize) -> Option<(f64, f32, usize)> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19,
        1e20, 1e21, 1e22,
    ];
    const POW10_F32: [f32; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];
    let negative = b.get(start) == Some(&b'-');
    let body = start + usize::from(negative || b.get(start) == Some(&b'+'));
    // The digits before the point, then those after it, into one mantissa (at most 20
    // digits: wrapping where 20 overflow, and refused below).
    let digit = |c: u8| c.wrapping_sub(b'0');
    let mut m = 0u64;
    let mut i = body;
    while i < b.len() && digit(b[i]) < 10 {
        m = m.wrapping_mul(10).wrapping_add(u64::from(digit(b[i])));
        i += 1;
    }
    let whole = i - body;
    let mut fraction = 0;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        let first = i;
        while i < b.len() && digit(b[i]) < 10 {
            m = m.wrapping_mul(10).wrapping_add(u64::from(digit(b[i])));
            i += 1;
        }
        fraction = i - first;
    }
    let digits = whole + fraction;
    if i - body > 20 || digits == 0 || digits > 19 || m > 1 << 53 || fraction >= POW10.len() {
        return None;
    }
    let sign = if negative { -1.0 } else { 1.0 };
    let x = sign * (m as f64 / POW10[fraction]);
    let f = if m <= 1 << 24 && fraction < POW10_F32.len() {
        sign as f32 * (m as f32 / POW10_F32[fraction])
    } else if (x.to_bits() & 0x1FFF_FFFF).abs_diff(0x1000_0000) > 1 {
        // The f64 is the value correctly rounded (within half its last place); rounding it
        // to f32 rounds the value itself unless the 29 bits it drops lie at a halfway point,
        // give or take that half place.
        x as f32
    } else {
        // (ASCII: a sign, digits and a point.)
        std::str::from_utf8(&b[start..i]).ok()?.parse::<f32>().ok()?
    };
    Some((x, f, i))
}

/// A corner's fields between its slashes (`r.split('/')`, without a generic searcher).
pub(super) fn slashed(r: &str) -> impl Iterator<Item = &str> {
    let mut rest = Some(r);
    std::iter::from_fn(move || {
        let s = rest?;
        match s.bytes().position(|b| b == b'/') {
            Some(i) => {
                rest = Some(&s[i + 1..]);
                Some(&s[..i])
            }
            None => {
                rest = None;
                Some(s)
            }
        }
    })
}

/// A word of ASCII digits, perhaps after a `-`, at most 18 of them, as the integer it is.
pub(super) fn plain_index(word: &str) -> Option<i64> {
    let b = word.as_bytes();
    let negative = b.first() == Some(&b'-');
    let digits = &b[usize::from(negative)..];
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v = 0i64;
    for &c in digits {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v * 10 + i64::from(c - b'0');
    }
    Some(if negative { -v } else { v })
}

/// Which vertex statement a line is, by its first word as [`words`] finds it: `Some(Some(k))`
/// for `v`, `vt` and `vn` (k = 0, 1, 2), `Some(None)` for another statement or none, `None` where
/// the line's start is not plain ASCII (then [`words`] must be asked).
pub(super) fn vertex_kind(line: &str) -> Option<Option<usize>> {
    let b = line.as_bytes();
    let white = |c: u8| matches!(c, b'\t'..=b'\r' | b' ');
    let i = b.iter().position(|&c| !white(c)).unwrap_or(b.len());
    // Whether a word ends at `j` (`None`: a byte outside ASCII there).
    let ends = |j: usize| match b.get(j) {
        None => Some(true),
        Some(&c) if white(c) || c == b'#' => Some(true),
        Some(c) => c.is_ascii().then_some(false),
    };
    match b.get(i) {
        None | Some(b'#') => Some(None),
        Some(b'v') => match b.get(i + 1) {
            Some(b't') => Some(ends(i + 2)?.then_some(1)),
            Some(b'n') => Some(ends(i + 2)?.then_some(2)),
            _ => Some(ends(i + 1)?.then_some(0)),
        },
        Some(c) if c.is_ascii() => Some(None),
        _ => None,
    }
}

/// An OBJ's text prepared for tobj, with what the preparation found (the reader as first
/// written, kept as the tests' second implementation of `read.rs`).
#[cfg(test)]
pub(super) struct Prepared {
    /// The text tobj reads, line for line the file's (so that locations stay right).
    pub text: String,
    /// What was skipped or repaired, for warnings.
    pub notes: Vec<String>,
    /// Subtracted from every position (in f64, before they become f32): the centre of a
    /// model that lies far from the origin, else zero.
    pub origin: DVec3,
}

/// Checks the OBJ records tobj would accept or reject without a location, and writes the
/// text as tobj reads it, line for line:
/// - numbers as `strtod` reads them, positions re-centred in f64 (see [`Prepared::origin`]);
/// - comments after a statement removed (tobj reads them as values);
/// - `v` records cut to `x y z` (a `w`, which the format gives no meaning for polygon
///   vertices and tobj divides by, is dropped; vertex colours `v x y z r g b` are kept where
///   every vertex has them, as tobj needs, else dropped with a warning), and `vt u` given its
///   `v` of 0;
/// - faces with fewer than 3 vertices removed, and a face's texture or normal indices that
///   refer to nothing dropped from that face (its normals are then computed);
/// - `l` and `p` statements removed (phong draws surfaces).
///
/// A vertex index out of range, a malformed number or a non-finite coordinate is an error at
/// its line and column.
#[cfg(test)]
pub(super) fn prepare_obj(path: &Path, src: &str) -> Result<Prepared, Error> {
    let joined = join_continuations(src);
    let src: &str = &joined;
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
    let origin = crate::models::far_origin(lines(src).filter_map(|(_, line)| {
        let w = words(line);
        if w.first().map(|w| w.1) != Some("v") || w.len() < 4 {
            return None;
        }
        let p: Vec<f64> = w[1..4].iter().filter_map(|(_, t)| strtod(t).map(|x| x.0)).collect();
        (p.len() == 3 && p.iter().all(|x| x.is_finite())).then(|| DVec3::new(p[0], p[1], p[2]))
    }));
    // Vertex colours are kept where every `v` has exactly `x y z r g b`.
    let mut vertices = lines(src)
        .map(|(_, l)| words(l))
        .filter(|w| w.first().is_some_and(|&(_, k)| k == "v"));
    let finite = |t: &str| strtod(t).is_some_and(|(x, _)| x.is_finite());
    let keep_colours = vertices.all(|w| w.len() == 7 && w[4..7].iter().all(|(_, t)| finite(t)));
    let mut out = String::with_capacity(src.len() + 64);
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    let (mut short_faces, mut bad_refs, mut colours, mut lenient) = (0usize, 0usize, 0usize, None);
    let (mut lines_, mut points, mut bad_colours, mut unnamed_materials) = (0usize, 0usize, 0usize, 0usize);
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
                for (i, (_, t)) in w.iter().enumerate().take(8).skip(used + 1) {
                    // A colour that is no finite number (`nan`): the colours are dropped, the
                    // positions kept.
                    if kw == "v" && w.len() == 7 && i >= 4 && strtod(t).is_some_and(|(x, _)| !x.is_finite()) {
                        bad_colours += 1;
                        continue;
                    }
                    number(i, &mut lenient)?;
                }
                if kw == "v" && w.len() > 6 && !keep_colours {
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
                if kw == "v" && keep_colours {
                    for i in 4..7 {
                        out.push(' ');
                        out.push_str(&(number(i, &mut lenient)? as f32).to_string());
                    }
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
            "usemtl" if w.len() == 1 => {
                // No name (assimp's test files): the default material from here on, as a name
                // that no library defines gives it.
                unnamed_materials += 1;
                out.push_str("usemtl ");
                out.push_str(NO_MATERIAL);
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
    if unnamed_materials > 0 {
        notes.push(format!(
            "{file}: {unnamed_materials} `usemtl` statements name no material: the default material there"
        ));
    }
    if bad_colours > 0 {
        notes.push(format!(
            "{file}: vertex colours are not used: {bad_colours} colour values are not finite numbers"
        ));
    } else if colours > 0 {
        notes.push(format!(
            "{file}: vertex colours ({colours} vertices) are not used: not every vertex has `x y z r g b`"
        ));
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
