//! The fast path's setup of a Phong- or Gouraud-interpolated object, lean in memory traffic:
//! per vertex a 20-byte [`FastVertex`] (and for Gouraud its lit colours), per triangle its
//! edges and plane equations; `ClipVertex` records are made only for the triangles that need
//! clipping.
//!
//! Gouraud vertices are lit after the triangles are set up, and only those of drawn triangles
//! (a sphere's back half is culled); the triangles wait as [`Pending`] until their colours
//! exist.

use super::Stage;
use super::{Chunk, Keep, Pending, SETUP_CHUNK, Scratch, Setup, VertexAttributes, plane_equations, uv_planes};
use crate::clip::{ClipVertex, Clipped, NOT_FINITE, OUTSIDE_CLIP, OUTSIDE_VIEW, clip_triangle};
use crate::fixed::each3;
use crate::plan::{Mode, lit_term};
use crate::simd::{ColourPlanes, Planes};
use crate::vertex::{FastVertex, VertexLighting, fast_vertices};
use glam::{Vec3, Vec4};
use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

impl Stage<'_> {
    /// Sets up object `oi` for the fast path, in chunks of [`SETUP_CHUNK`] input triangles,
    /// each binned.
    pub(super) fn object_fast(&self, oi: usize, scratch: &mut Scratch, spare: &Mutex<Vec<Chunk>>) -> Vec<Chunk> {
        let obj = &self.scene.objects[oi];
        let plan = &self.plan.objects[oi];
        let (isa, clip_from_world) = (self.plan.isa, self.plan.clip_from_world);
        let (two_sided, colour) = (obj.shading.options.two_sided, self.plan.colour_planes);
        // Lit per vertex (Gouraud, textured or not), and textured.
        let gouraud = matches!(plan.mode, Mode::Gouraud | Mode::Textured { per_vertex: true, .. });
        let textured = matches!(plan.mode, Mode::Textured { .. });
        // A flat mesh's normals per triangle; lit per vertex, three vertices a triangle.
        let mesh = if gouraud {
            obj.mesh.with_vertex_normals()
        } else {
            &obj.mesh
        };
        let (positions, normals, faces) = (mesh.positions(), mesh.normals(), mesh.face_normals());
        // The normals at a triangle's corners.
        let corner_normals = |f: usize, tri: [u32; 3]| match faces {
            Some(faces) => [faces[f]; 3],
            None => tri.map(|i| normals[i as usize]),
        };
        self.fast_vertices(&mut scratch.vertices, positions);
        let attrs = VertexAttributes(mesh);
        let extra = plan.extra;
        let extra_of = |i: u32| extra.of(attrs.rgb(i), attrs.uv1(i), attrs.tangent(i));
        let lighting = gouraud.then(|| {
            let term = lit_term(obj.shading.output).expect("Gouraud mode is a lit output");
            VertexLighting::new(isa, &self.scene.lighting, obj, plan.view, term, two_sided, textured)
        });
        if gouraud {
            unmark(&mut scratch.used, positions.len());
        }
        let (vertices, used) = (&*scratch.vertices, &*scratch.used);
        let mark = |idx: [u32; 3]| {
            for i in idx {
                used[i as usize].store(true, Ordering::Relaxed);
            }
        };
        // The planes of a set-up triangle from its input vertices' indices and its normals
        // (Phong).
        let phong_planes = |s: &Setup, idx: [u32; 3], ns: [Vec3; 3]| -> Planes {
            let (idx, ns) = (each3(|k| idx[s.order[k]] as usize), each3(|k| ns[s.order[k]]));
            let sign = if s.front { 1.0 } else { -1.0 };
            let attrs = [
                [positions[idx[0]], positions[idx[1]], positions[idx[2]]],
                [ns[0] * sign, ns[1] * sign, ns[2] * sign],
            ];
            plane_equations(s.xy[0], &s.tri, s.area, s.inv_w, attrs, false)
        };
        let setup_chunk = |(c, chunk): (usize, &[[u32; 3]])| {
            let mut out = Chunk::reuse(spare, oi, chunk.len());
            out.reserve_planes(colour, chunk.len());
            for (f, &tri) in (c * SETUP_CHUNK..).zip(chunk) {
                let v = [
                    vertices[tri[0] as usize],
                    vertices[tri[1] as usize],
                    vertices[tri[2] as usize],
                ];
                let c = [v[0].code, v[1].code, v[2].code];
                if c[0] & c[1] & c[2] & OUTSIDE_VIEW != 0 {
                    continue;
                }
                if (c[0] | c[1] | c[2]) & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
                    if let Some(s) = self.setup_edges([v[0].p, v[1].p, v[2].p], two_sided) {
                        if gouraud {
                            mark(tri);
                            out.pending.push(Pending {
                                slot: out.tris.len() as u32,
                                idx: each3(|k| tri[s.order[k]]),
                            });
                        } else {
                            out.planes.push(phong_planes(&s, tri, corner_normals(f, tri)));
                        }
                        if textured {
                            let idx = each3(|k| tri[s.order[k]]);
                            out.uv
                                .push(uv_planes(&s, idx.map(|i| attrs.uv(i)), idx.map(extra_of), extra));
                        }
                        out.tris.push(s.tri);
                    }
                    continue;
                }
                // Rare: clip, with the vertices in full (Gouraud: lit here).
                let mut lit3 = [[Vec3::ZERO; 3]; 4];
                let ns = corner_normals(f, tri);
                if let Some(lighting) = &lighting {
                    let ps = tri.map(|i| positions[i as usize]);
                    lighting.light(&ps, &ns, lit3.each_mut().map(|c| &mut c[..]));
                }
                let t = each3(|k| {
                    let i = tri[k] as usize;
                    ClipVertex {
                        clip: clip_from_world * Vec4::from((positions[i], 1.0)),
                        world: positions[i],
                        normal: ns[k],
                        color: lit3[0][k],
                        color_back: lit3[1][k],
                        spec: [lit3[2][k], lit3[3][k]],
                        uv: attrs.uv(tri[k]),
                        uv1: attrs.uv1(tri[k]),
                        rgb: attrs.rgb(tri[k]),
                        tangent: attrs.tangent(tri[k]),
                    }
                });
                let mut push = |t: [ClipVertex; 3]| {
                    if let Some((tri, p, _, uv)) = self.setup(
                        t,
                        None,
                        None,
                        oi as u32,
                        Keep {
                            corners: false,
                            planes: true,
                        },
                    ) {
                        if gouraud {
                            out.clipped.push((out.tris.len() as u32, p));
                        } else {
                            out.planes.push(p);
                        }
                        out.uv.extend(uv);
                        out.tris.push(tri);
                    }
                };
                match clip_triangle(&t) {
                    Clipped::Rejected => {}
                    Clipped::Inside => push(t),
                    Clipped::Polygon(p) => {
                        for i in 1..p.len() - 1 {
                            push([p[0], p[i], p[i + 1]]);
                        }
                    }
                }
            }
            self.bin_entries(&mut out);
            out
        };
        let mut chunks: Vec<Chunk> = mesh
            .triangles()
            .par_chunks(SETUP_CHUNK)
            .enumerate()
            .map(setup_chunk)
            .collect();
        if let Some(lighting) = &lighting {
            // Lit straight into the colour arrays, which keep last frame's values: only the
            // used vertices' colours are read.
            lighting.light_used(positions, normals, used, &mut scratch.colors);
            gouraud_planes(&mut chunks, vertices, &scratch.colors, textured, colour);
        }
        chunks
    }

    /// Each of `positions` projected into its [`FastVertex`] record in `vertices`.
    fn fast_vertices(&self, vertices: &mut Vec<FastVertex>, positions: &[Vec3]) {
        let (isa, clip_from_world) = (self.plan.isa, self.plan.clip_from_world);
        // Every record is overwritten below: keep last frame's (no fill) where there are enough.
        vertices.truncate(positions.len());
        vertices.resize(positions.len(), FastVertex::default());
        vertices
            .par_chunks_mut(SETUP_CHUNK)
            .zip(positions.par_chunks(SETUP_CHUNK))
            .for_each(|(out, ps)| fast_vertices(isa, clip_from_world, (self.plan.w, self.plan.h), ps, out));
    }
}

/// The planes of the Gouraud triangles that waited for their vertices' colours
/// ([`Pending`]), made from `colors` (front, back and, textured, their
/// specular colours) once the used vertices are lit; each chunk's clipped triangles' planes,
/// made at setup, are taken in slot order.
/// `colour`: kept as [`ColourPlanes`] (`FramePlan::colour_planes`).
fn gouraud_planes(
    chunks: &mut [Chunk],
    vertices: &[FastVertex],
    colors: &[Vec<Vec3>; 4],
    textured: bool,
    colour: bool,
) {
    chunks.par_iter_mut().for_each(|chunk| {
        let Chunk {
            tris,
            planes,
            colour: colour_planes,
            pending,
            clipped,
            ..
        } = chunk;
        // In slot order: the pending triangles' planes made here, the clipped ones'
        // taken (no default planes written first: 96 bytes a triangle).
        let (mut pending, mut clipped) = (pending.iter().peekable(), clipped.iter().peekable());
        let each = (0..tris.len() as u32).map(|slot| {
            if let Some(p) = pending.next_if(|p| p.slot == slot) {
                let t = &tris[slot as usize];
                let v = each3(|k| vertices[p.idx[k] as usize].p);
                // Twice the area: the cross product of edges 2 (vertex 0 to 1) and 1
                // (vertex 2 to 0), as `setup_edges` computed it up to the sign.
                let area = (t.a(1) * t.b(2) - t.a(2) * t.b(1)).unsigned_abs();
                let side = usize::from(t.back);
                let c = each3(|k| colors[side][p.idx[k] as usize]);
                // Textured: the specular colours too (`VertexLighting::light`).
                let s = if textured {
                    each3(|k| colors[2 + side][p.idx[k] as usize])
                } else {
                    [Vec3::ZERO; 3]
                };
                plane_equations(
                    (i64::from(v[0].0), i64::from(v[0].1)),
                    t,
                    area,
                    [v[0].3, v[1].3, v[2].3],
                    [c, s],
                    !textured,
                )
            } else {
                let c = clipped.next();
                debug_assert_eq!(c.map(|c| c.0), Some(slot), "every slot is pending or clipped");
                c.map(|c| c.1).unwrap_or_default()
            }
        });
        if colour {
            colour_planes.extend(each.map(|p| ColourPlanes::from(&p)));
        } else {
            planes.extend(each);
        }
    });
}

/// `used` as `n` flags, all false (last frame's memory kept).
fn unmark(used: &mut Vec<AtomicBool>, n: usize) {
    used.truncate(n);
    used.par_iter().for_each(|u| u.store(false, Ordering::Relaxed));
    used.resize_with(n, || AtomicBool::new(false));
}
