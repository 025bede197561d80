//! STL, binary and ASCII. The two are told apart by content, not by the first word: a binary
//! file's size is 84 + 50 bytes a facet (its 80-byte header may begin with `solid`, as many
//! exporters write), and an ASCII file is `solid [name]` then facets. Binary files are read as
//! arrays of facets; ASCII ones line by line, every `solid ... endsolid` block a part (CAD tools write one a
//! body), with a located error for what is not STL.

use super::ModelPart;
use super::{far_origin, model_error, part_name};
use crate::Error;
use glam::{DVec3, Vec3};
use phong_core::Mesh;
use rustc_hash::FxHashMap;
use std::path::Path;

/// One `solid` block: its name (possibly empty) and its facets' corners.
type Solid = (String, Vec<[Vec3; 3]>);

/// The parts of the STL file `path` whose bytes are `bytes`.
pub(crate) fn read_stl(path: &Path, bytes: &[u8]) -> Result<Vec<ModelPart>, Error> {
    let fail = |m: String| model_error(path, format!("malformed STL: {m}"));
    let binary = bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
        84 + 50 * u64::from(n) == bytes.len() as u64
    };
    let text = (!binary).then(|| std::str::from_utf8(bytes).ok()).flatten();
    let solids = match text {
        Some(t) if t.trim_start().starts_with("solid") => ascii_solids(t).map_err(fail)?,
        _ => vec![(String::new(), binary_facets(bytes).map_err(fail)?)],
    };
    let several = solids.len() > 1;
    let indexed: Vec<_> = solids.iter().map(|(_, corners)| indexed(corners)).collect();
    for (points, _) in &indexed {
        if let Some((i, p)) = points.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(fail(format!("vertex {i} is not finite: {p}")));
        }
    }
    // Every part is re-centred on one point, so that the parts keep their places.
    let origin = far_origin(
        indexed
            .iter()
            .flat_map(|(points, _)| points.iter().map(|p| p.as_dvec3())),
    );
    let mut parts = Vec::new();
    for (i, ((name, _), (points, triangles))) in solids.into_iter().zip(indexed).enumerate() {
        if triangles.is_empty() {
            continue;
        }
        let positions: Vec<Vec3> = if origin == DVec3::ZERO {
            points
        } else {
            points.iter().map(|p| (p.as_dvec3() - origin).as_vec3()).collect()
        };
        let normals = vec![Vec3::ZERO; positions.len()];
        let mesh = Mesh::new(positions, normals, triangles).map_err(|e| fail(e.to_string()))?;
        let base = part_name(path);
        parts.push(ModelPart {
            name: match (several, name.is_empty()) {
                (false, _) => base,
                (true, true) => format!("{base}#{}", i + 1),
                (true, false) => format!("{base}:{name}"),
            },
            mesh,
            material: None,
            maps: phong_core::Maps::default(),
            has_normals: false,
            flat_without_normals: false,
            origin,
            drawn: None,
            fitted: None,
        });
    }
    if parts.is_empty() {
        return Err(fail("no facets: nothing to render".into()));
    }
    Ok(parts)
}

/// The facets of a binary STL: after an 80-byte header and a count, 50 bytes a facet (a
/// normal, three corners as little-endian f32, two bytes of attributes). Bytes after the last
/// facet are ignored, as other readers do.
fn binary_facets(bytes: &[u8]) -> Result<Vec<[Vec3; 3]>, String> {
    let Some(count) = bytes.get(80..84) else {
        return Err(format!(
            "{} bytes: neither a binary STL (an 84-byte header, then 50 bytes a facet) nor an ASCII one",
            bytes.len()
        ));
    };
    let n = u32::from_le_bytes(count.try_into().expect("4 bytes")) as usize;
    let body = &bytes[84..];
    if body.len() / 50 < n {
        return Err(format!(
            "the header counts {n} facets, the file holds {} (50 bytes a facet); an ASCII STL begins with `solid`",
            body.len() / 50
        ));
    }
    Ok(body
        .chunks_exact(50)
        .take(n)
        .map(|b| {
            let corners: &[u8; 36] = b[12..48].try_into().expect("36 bytes");
            let mut v = [0.0f32; 9];
            for (x, w) in v.iter_mut().zip(corners.chunks_exact(4)) {
                *x = f32::from_le_bytes(w.try_into().expect("4 bytes"));
            }
            [
                Vec3::new(v[0], v[1], v[2]),
                Vec3::new(v[3], v[4], v[5]),
                Vec3::new(v[6], v[7], v[8]),
            ]
        })
        .collect())
}

/// Corners with equal coordinates (bit for bit) as one vertex, in order of first use.
fn indexed(corners: &[[Vec3; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut index: FxHashMap<[u32; 3], u32> = FxHashMap::with_capacity_and_hasher(corners.len(), Default::default());
    let mut points = Vec::with_capacity(corners.len() / 2);
    let triangles = corners
        .iter()
        .map(|t| {
            t.map(|v| {
                *index.entry(v.to_array().map(f32::to_bits)).or_insert_with(|| {
                    points.push(v);
                    (points.len() - 1) as u32
                })
            })
        })
        .collect();
    (points, triangles)
}

/// The facets of each `solid ... endsolid` block of an ASCII STL (a block's name, possibly
/// empty), or a message naming the line.
fn ascii_solids(text: &str) -> Result<Vec<Solid>, String> {
    let mut solids: Vec<Solid> = Vec::new();
    let mut open = false;
    let mut corners: Vec<Vec3> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let at = |m: String| format!("line {}: {m}", n + 1);
        let mut words = line.split_whitespace();
        let Some(first) = words.next() else { continue };
        match first {
            "solid" if !open => {
                open = true;
                solids.push((words.collect::<Vec<_>>().join(" "), Vec::new()));
            }
            "endsolid" if open => open = false,
            "facet" | "outer" | "endloop" if open => {}
            "vertex" if open => {
                let v: Vec<f32> = words
                    .map(|w| w.parse::<f32>().map_err(|_| at(format!("`{w}` is not a number"))))
                    .collect::<Result<_, _>>()?;
                if v.len() != 3 {
                    return Err(at(format!("a vertex has 3 coordinates, got {}", v.len())));
                }
                corners.push(Vec3::new(v[0], v[1], v[2]));
            }
            "endfacet" if open => {
                if corners.len() != 3 {
                    return Err(at(format!("a facet has 3 vertices, got {}", corners.len())));
                }
                let t = [corners[0], corners[1], corners[2]];
                solids.last_mut().expect("inside a solid").1.push(t);
                corners.clear();
            }
            w => {
                let why = if open {
                    "inside a solid"
                } else {
                    "outside a solid (`solid NAME` ... `endsolid`)"
                };
                return Err(at(format!("unexpected `{w}` {why}")));
            }
        }
    }
    Ok(solids)
}
