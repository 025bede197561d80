//! The setup of an object for the reference path, for the fast path's scalar shading
//! (textured objects it does not cover, normal and depth outputs, blended objects), and for
//! its flat-shaded and alpha-tested objects: every vertex in full, lit per vertex (Gouraud) or
//! per triangle (flat) by `Object::vertex_light` (a textured object: its primary and specular
//! colours, for the texels applied per pixel; on the fast path, flat triangles by the vector
//! kernel, all at once), [`Corners`] and planes kept as asked.

use super::Stage;
use super::{Chunk, Corners, Flat, Keep, SETUP_CHUNK, Tri, VertexAttributes};
use crate::clip::{ClipVertex, Clipped, NOT_FINITE, OUTSIDE_CLIP, OUTSIDE_VIEW, clip_triangle, outcode};
use crate::plan::lit_term;
use crate::simd::Planes;
use crate::vertex::{Projected, VertexLighting};
use glam::{Vec3, Vec4};
use phong_core::mesh::facet_normal;
use phong_core::{Color, Interpolation};
use rayon::prelude::*;

impl Stage<'_> {
    /// Sets up object `oi` with what `keep` asks for: [`Corners`] for scalar shading (or the
    /// alpha test), fast-path planes (a flat-shaded or alpha-tested object on the fast path),
    /// in chunks of [`SETUP_CHUNK`] input triangles, each binned.
    pub(super) fn object_full(&self, oi: usize, keep: Keep) -> Vec<Chunk> {
        let scene = self.scene;
        let obj = &scene.objects[oi];
        let clip_from_world = self.plan.clip_from_world;
        let interpolation = obj.shading.interpolation;
        let two_sided = obj.shading.options.two_sided;
        let view = self.plan.objects[oi].view;
        // (A flat mesh as three vertices a triangle: this path reads normals per vertex.)
        let mesh = obj.mesh.with_vertex_normals();
        let (gouraud, colour) = (interpolation == Interpolation::Gouraud, self.plan.colour_planes);
        let attrs = VertexAttributes(mesh);
        let lit = |p: Vec3, n: Vec3| obj.vertex_light(&scene.lighting, &view, p, n);
        let vec3 = |c: Color| Vec3::from(c.to_array());
        let color = |v: Vec3| Color::new(v.x, v.y, v.z);
        // Flat on the fast path: every triangle lit at once at its centroid by the vector
        // kernel, as Gouraud vertices are (the reference lights each with `vertex_light`); with
        // the facet normals, kept for the triangles' planes.
        let flat_lit = (keep.planes && interpolation == Interpolation::Flat)
            .then(|| lit_term(obj.shading.output))
            .flatten()
            .map(|term| {
                let lighting = VertexLighting::new(
                    self.plan.isa,
                    &scene.lighting,
                    obj,
                    view,
                    term,
                    two_sided,
                    obj.textured(),
                );
                let p = mesh.positions();
                let (centroids, normals): (Vec<Vec3>, Vec<Vec3>) = mesh
                    .triangles()
                    .par_iter()
                    .map(|t| {
                        let [a, b, c] = t.map(|i| p[i as usize]);
                        ((a + b + c) / 3.0, facet_normal(a, b, c))
                    })
                    .unzip();
                (lighting.light_all(&centroids, &normals), normals)
            });
        let verts: Vec<ClipVertex> = mesh
            .positions()
            .par_iter()
            .zip(mesh.normals().par_iter())
            .enumerate()
            .map(|(i, (&p, &n))| {
                let front = if gouraud {
                    lit(p, n)
                } else {
                    (Color::BLACK, Color::BLACK)
                };
                let back = if gouraud && two_sided {
                    lit(p, -n)
                } else {
                    (Color::BLACK, Color::BLACK)
                };
                ClipVertex {
                    clip: clip_from_world * Vec4::from((p, 1.0)),
                    world: p,
                    normal: n,
                    color: vec3(front.0),
                    color_back: vec3(back.0),
                    spec: [vec3(front.1), vec3(back.1)],
                    uv: attrs.uv(i as u32),
                    uv1: attrs.uv1(i as u32),
                    rgb: attrs.rgb(i as u32),
                    tangent: attrs.tangent(i as u32),
                }
            })
            .collect();
        // Per vertex, once: its outcode, and its projection where it is inside the clipping
        // planes (a vertex is shared by about six triangles).
        let codes: Vec<u16> = verts.par_iter().map(|v| outcode(v.clip)).collect();
        let projected: Vec<Projected> = verts
            .par_iter()
            .zip(&codes)
            .map(|(v, &code)| {
                if code & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
                    self.project(v.clip)
                } else {
                    Projected::default()
                }
            })
            .collect();
        let setup_chunk = |(ci, chunk): (usize, &[[u32; 3]])| {
            let mut out = Chunk {
                object: oi as u32,
                tris: Vec::with_capacity(chunk.len()),
                ..Chunk::default()
            };
            let mut push = |r: Option<(Tri, Planes, Option<Corners>, Option<Planes>)>| {
                if let Some((t, p, c, uv)) = r {
                    out.tris.push(t);
                    out.corners.extend(c);
                    if keep.planes {
                        out.push_planes(colour, &p);
                        out.uv.extend(uv);
                    }
                }
            };
            for (k, tri) in chunk.iter().enumerate() {
                let c = tri.map(|i| codes[i as usize]);
                if c[0] & c[1] & c[2] & OUTSIDE_VIEW != 0 {
                    continue;
                }
                let t = tri.map(|i| verts[i as usize]);
                // Flat: front and (two-sided) back colours, from the facet normal at the centroid.
                let flat = (interpolation == Interpolation::Flat).then(|| -> [Flat; 2] {
                    let (fnorm, front, back) = match &flat_lit {
                        Some(([f, b, fs, bs], normals)) => {
                            let i = ci * SETUP_CHUNK + k;
                            let at = |v: &Vec<Vec3>| v.get(i).map_or(Color::BLACK, |&c| color(c));
                            let front = (at(f), at(fs));
                            (normals[i], front, if two_sided { (at(b), at(bs)) } else { front })
                        }
                        None => {
                            let fnorm = facet_normal(t[0].world, t[1].world, t[2].world);
                            let centroid = (t[0].world + t[1].world + t[2].world) / 3.0;
                            let front = lit(centroid, fnorm);
                            (fnorm, front, if two_sided { lit(centroid, -fnorm) } else { front })
                        }
                    };
                    [(front.0, front.1, fnorm), (back.0, back.1, -fnorm)]
                });
                if (c[0] | c[1] | c[2]) & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
                    let proj = tri.map(|i| projected[i as usize]);
                    push(self.setup(t, Some(proj), flat, oi as u32, keep));
                    continue;
                }
                match clip_triangle(&t) {
                    Clipped::Rejected => {}
                    Clipped::Inside => push(self.setup(t, None, flat, oi as u32, keep)),
                    Clipped::Polygon(p) => {
                        for i in 1..p.len() - 1 {
                            push(self.setup([p[0], p[i], p[i + 1]], None, flat, oi as u32, keep));
                        }
                    }
                }
            }
            self.bin_entries(&mut out);
            out
        };
        mesh.triangles()
            .par_chunks(SETUP_CHUNK)
            .enumerate()
            .map(setup_chunk)
            .collect()
    }
}
