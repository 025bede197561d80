//! The vertex stage: clip-space transform, outcode and window projection of each vertex, and
//! (Gouraud) the lighting of the vertices that drawn triangles use.

use crate::clip::{NOT_FINITE, OUTSIDE_CLIP, outcode};
use crate::fixed::{ONE, round_i64};
use crate::simd::{Isa, Lean, Prepared, Term, VertexTerm, light_vertices, light_vertices_lit, project_vertices};
use glam::{Mat4, Vec3, Vec4};
use phong_core::{Lighting, Object, View};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Vertices lit together: a group is lit when any of its vertices is used (the kernel's 16
/// lanes).
const LIGHT_GROUP: usize = 16;
/// Vertices per parallel lighting task.
const LIGHT_CHUNK: usize = 4096;

/// A vertex in the window: snapped `x`, `y` (1/256 pixel; the guard band keeps them below
/// 2^24), depth, `1/w`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Projected(pub i32, pub i32, pub f32, pub f32);

/// A vertex of the fast path's setup: its projection (where inside the clipping planes) and
/// outcode. 20 bytes: the fast setup reads these, not 64-byte `ClipVertex` copies.
#[derive(Clone, Copy, Default)]
pub(crate) struct FastVertex {
    pub p: Projected,
    pub code: u16,
}

/// Clip-space `c` (`w > 0`) to a `w × h` window: snapped `x`, `y` (1/256 pixel), depth in
/// [0, 1] and `1/w`.
#[inline]
pub(crate) fn project(c: Vec4, w: u32, h: u32) -> Projected {
    let (p, iw) = phong_core::window_from_clip(c, w as f32, h as f32);
    Projected(round_i64(p.x * ONE) as i32, round_i64(p.y * ONE) as i32, p.z, iw)
}

/// The fast setup's records of `positions` into `out`, for a `w × h` window: clip-space
/// transform, outcode and (inside the clip volume) projection; the AVX2 kernel's are the
/// same bits (see `simd/project.rs`).
pub(crate) fn fast_vertices(
    isa: Isa,
    clip_from_world: Mat4,
    (w, h): (u32, u32),
    positions: &[Vec3],
    out: &mut [FastVertex],
) {
    let scalar = |p: Vec3| {
        let clip = clip_from_world * Vec4::from((p, 1.0));
        let code = outcode(clip);
        let p = if code & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
            project(clip, w, h)
        } else {
            Projected::default()
        };
        FastVertex { p, code }
    };
    project_vertices(
        isa,
        &clip_from_world,
        (w as f32, h as f32, ONE),
        positions,
        out,
        |([x, y], z, inv_w, code)| FastVertex {
            p: Projected(x, y, z, inv_w),
            code,
        },
        scalar,
    );
}

/// Gouraud's vertex lighting of one object: the kernel's term at each vertex, seen from the
/// front and (two-sided) from the back; for a textured object, its primary and specular
/// colours (`phong_core::Lit`), which the texels modulate per pixel. A vertex lit alone or
/// among others gives the same bits (the kernel's lanes are independent).
pub(crate) struct VertexLighting {
    pub isa: Isa,
    pub prepared: Prepared,
    pub term: Term,
    pub two_sided: bool,
    /// Textured: the primary and specular colours apart.
    pub textured: bool,
    /// The lean kernel's data where it lights the vertices (the colour term of the objects it
    /// covers: `simd/lean.rs`).
    pub lean: Option<Lean>,
}

/// A numbered piece of the front colours, with the same piece of the back, front specular and
/// back specular colours.
type Piece<'a> = (usize, (&'a mut [Vec3], [&'a mut [Vec3]; 3]));

/// The four outputs of [`VertexLighting::light`] cut into pieces of [`LIGHT_CHUNK`] points,
/// numbered: the front colours' piece with the others' (empty where they are).
fn pieces(colors: &mut [Vec<Vec3>; 4]) -> Vec<Piece<'_>> {
    let [front, back, front_specular, back_specular] = colors;
    let mut others = [back, front_specular, back_specular].map(|c| c.chunks_mut(LIGHT_CHUNK));
    front
        .chunks_mut(LIGHT_CHUNK)
        .map(|f| (f, others.each_mut().map(|o| o.next().unwrap_or_default())))
        .enumerate()
        .collect()
}

impl VertexLighting {
    /// The lighting of `obj`'s vertices under `lighting` seen from `view`: `term`, by the lean
    /// kernel where it covers them.
    pub fn new(
        isa: Isa,
        lighting: &Lighting,
        obj: &Object,
        view: View,
        term: Term,
        two_sided: bool,
        textured: bool,
    ) -> VertexLighting {
        let prepared = Prepared::new(lighting, &obj.material, &obj.shading.options, view);
        let lean = if !textured && term == Term::Color {
            Lean::of(&prepared)
        } else {
            None
        };
        VertexLighting {
            isa,
            prepared,
            term,
            two_sided,
            textured,
            lean,
        }
    }

    /// The colours of vertices `ps` with normals `ns`: `out[0]` from the front, `out[1]` from
    /// the back (two-sided only); textured, those are the primary colours and `out[2]`,
    /// `out[3]` the specular ones (else not written).
    pub fn light(&self, ps: &[Vec3], ns: &[Vec3], out: [&mut [Vec3]; 4]) {
        let sides = if self.two_sided { 2 } else { 1 };
        let [front, back, front_specular, back_specular] = out;
        let sides_out = [[front, front_specular], [back, back_specular]];
        for (side, [o, spec]) in sides_out.into_iter().enumerate().take(sides) {
            if self.textured {
                light_vertices_lit(self.isa, &self.prepared, ps, ns, side == 1, [o, spec]);
            } else {
                let term = match &self.lean {
                    Some(lean) => VertexTerm::Lean(lean),
                    None => VertexTerm::General(self.term),
                };
                light_vertices(self.isa, &self.prepared, term, ps, ns, side == 1, o);
            }
        }
    }

    /// Every point of `ps` (normals `ns`) lit, on all cores: [`VertexLighting::light`]'s four
    /// outputs, each as long as `ps` where it is written, else empty.
    pub fn light_all(&self, ps: &[Vec3], ns: &[Vec3]) -> [Vec<Vec3>; 4] {
        let mut colors = <[Vec<Vec3>; 4]>::default();
        self.size(&mut colors, ps.len());
        pieces(&mut colors).into_par_iter().for_each(|(j, (f, [b, fs, bs]))| {
            let range = j * LIGHT_CHUNK..j * LIGHT_CHUNK + f.len();
            self.light(&ps[range.clone()], &ns[range], [f, b, fs, bs]);
        });
        colors
    }

    /// `colors` resized to `n` points where [`VertexLighting::light`] writes them, else empty.
    fn size(&self, colors: &mut [Vec<Vec3>; 4], n: usize) {
        let lengths = [
            n,
            if self.two_sided { n } else { 0 },
            if self.textured { n } else { 0 },
            if self.textured && self.two_sided { n } else { 0 },
        ];
        for (c, len) in colors.iter_mut().zip(lengths) {
            c.resize(len, Vec3::ZERO);
        }
    }

    /// Lights, into `colors` (as [`VertexLighting::light`]'s `out`, resized to the mesh; the
    /// other vertices keep what they held), the vertices that `used` marks, by runs of
    /// 16-vertex groups with a used vertex, one kernel call a run.
    pub fn light_used(&self, positions: &[Vec3], normals: &[Vec3], used: &[AtomicBool], colors: &mut [Vec<Vec3>; 4]) {
        self.size(colors, positions.len());
        let jobs = pieces(colors);
        jobs.into_par_iter().for_each(|(j, (f, mut o))| {
            let at = j * LIGHT_CHUNK;
            let range = at..at + f.len();
            let (ps, ns, us) = (&positions[range.clone()], &normals[range.clone()], &used[range]);
            let group_used = |g: usize| {
                us[g * LIGHT_GROUP..((g + 1) * LIGHT_GROUP).min(us.len())]
                    .iter()
                    .any(|u| u.load(Ordering::Relaxed))
            };
            let (groups, mut g) = (us.len().div_ceil(LIGHT_GROUP), 0);
            while g < groups {
                if !group_used(g) {
                    g += 1;
                    continue;
                }
                let start = g;
                while g < groups && group_used(g) {
                    g += 1;
                }
                let run = start * LIGHT_GROUP..(g * LIGHT_GROUP).min(us.len());
                let [b, fs, bs] = o
                    .each_mut()
                    .map(|c| if c.is_empty() { &mut [][..] } else { &mut c[run.clone()] });
                self.light(&ps[run.clone()], &ns[run.clone()], [&mut f[run], b, fs, bs]);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::xorshift;

    #[test]
    fn vertex_record_is_20_bytes() {
        assert_eq!(std::mem::size_of::<FastVertex>(), 20);
    }

    /// The AVX2 vertex stage gives the scalar one's records bit for bit: vertices in front of,
    /// across and behind a perspective camera, in and far beyond the guard band, at the eye
    /// (`w = 0`), NaN and infinite, in groups of 8 and a remainder; and through a degenerate
    /// transform whose every vertex is "inside" at `w = 0`.
    #[test]
    fn vector_vertex_stage_matches_scalar() {
        let Some(avx2) = crate::testkit::avx2() else {
            return;
        };
        let camera = phong_core::Camera::new(
            Vec3::new(0.3, 0.2, 3.0),
            Vec3::ZERO,
            Vec3::Y,
            phong_core::Projection::Perspective { fov_y_deg: 50.0 },
            0.1,
            50.0,
        )
        .expect("a valid camera");
        let clip_from_world = camera.clip_from_world(16.0 / 9.0);
        let mut bits = xorshift(0x0123_4567_89ab_cdef);
        let mut next = || (bits() >> 40) as f32 / (1u64 << 24) as f32;
        let mut positions: Vec<Vec3> = (0..20_000)
            .map(|i| {
                let scale = [1.5, 6.0, 400.0][i % 3];
                Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale
            })
            .collect();
        for (i, p) in [
            Vec3::new(0.3, 0.2, 3.0),
            Vec3::new(0.3, 0.2, 2.95),
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::new(0.0, f32::INFINITY, 0.0),
            Vec3::new(1e30, -1e30, 0.0),
        ]
        .into_iter()
        .enumerate()
        {
            positions[i * 37 + 5] = p;
        }
        positions.truncate(19_997);
        let vertex = FastVertex::default();
        let (mut fast, mut slow) = (vec![vertex; positions.len()], vec![vertex; positions.len()]);
        for (w, h) in [(1920, 1080), (333, 517)] {
            fast_vertices(avx2, clip_from_world, (w, h), &positions, &mut fast);
            fast_vertices(Isa::PORTABLE, clip_from_world, (w, h), &positions, &mut slow);
            let bits = |v: &FastVertex| (v.p.0, v.p.1, v.p.2.to_bits(), v.p.3.to_bits(), v.code);
            let mut inside = 0;
            for (i, (a, b)) in fast.iter().zip(&slow).enumerate() {
                assert_eq!(bits(a), bits(b), "vertex {i} at {}", positions[i]);
                inside += usize::from(b.code & (OUTSIDE_CLIP | NOT_FINITE) == 0);
            }
            assert!(
                inside > 2_000 && inside < 18_000,
                "{inside} of the vertices inside the clip volume"
            );
        }
        // A degenerate transform: every vertex at clip-space (0, 0, 0, 0), inside every plane,
        // projected through 1/0 to NaN: the kernel's groups go to the scalar code's casts.
        let zero = Mat4::ZERO;
        fast_vertices(avx2, zero, (64, 64), &positions[..20], &mut fast[..20]);
        fast_vertices(Isa::PORTABLE, zero, (64, 64), &positions[..20], &mut slow[..20]);
        for (a, b) in fast[..20].iter().zip(&slow[..20]) {
            assert_eq!((a.p.0, a.p.1, a.code), (b.p.0, b.p.1, b.code));
            assert_eq!((a.p.2.is_nan(), a.p.3.to_bits()), (b.p.2.is_nan(), b.p.3.to_bits()));
        }
    }
}
