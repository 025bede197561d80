//! `[[object]]`: a shape or a mesh file, its transform, material and shading.

use super::choices::SHAPES;
use super::ctx::{Ctx, S};
use super::material::{Mat, lookup_material, material};
use super::raw::{MaterialRef, RawMaterial, RawObject, Scale};
use crate::Error;
use crate::{ModelFile, ModelPart};
use glam::{EulerRot, Mat4, Quat, Vec3};
use phong_core::limits::MAX_SEGMENTS;
use phong_core::{Maps, Mesh, Object, ShadingSettings, primitives};
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

pub(super) fn object(
    ctx: &mut Ctx,
    o: &S<RawObject>,
    named: &BTreeMap<String, Mat>,
    shading: ShadingSettings,
) -> Result<Vec<Object>, Error> {
    let span = o.span();
    let o = o.get_ref();
    let material = match &o.material {
        None => None,
        Some(m) => Some(match m.get_ref() {
            MaterialRef::Name(n) => lookup_material(ctx, &Spanned::new(m.span(), n.clone()), named)?,
            MaterialRef::Inline(p) => inline_material(ctx, m, p, named)?,
        }),
    };
    let world_from_object = transform(ctx, o)?;
    match (&o.shape, &o.mesh) {
        (Some(_), Some(m)) => ctx.err(&m.span(), "mesh", "an object has either `shape` or `mesh`, not both"),
        (Some(shape), None) => shape_object(ctx, o, span, shape, world_from_object, material, shading),
        (None, Some(m)) => mesh_objects(ctx, o, m, world_from_object, material, shading),
        (None, None) => ctx.err(
            &span,
            "object",
            "an object needs `shape` (sphere, torus, ...) or `mesh` (a file)",
        ),
    }
}

/// The crease angle of `normals = "angle"` where the object gives none, in degrees.
pub(crate) const DEFAULT_CREASE: f32 = 60.0;

/// The object's `crease` (degrees, for `normals = "angle"`; [`DEFAULT_CREASE`] by default).
fn crease(ctx: &mut Ctx, o: &RawObject) -> Result<f32, Error> {
    match &o.crease {
        Some(c) => ctx.num(c, "crease", |x| (0.0..=180.0).contains(&x), "in [0, 180] degrees"),
        None => Ok(DEFAULT_CREASE),
    }
}

/// An inline material table (`material = { ... }`) as the scene's `[materials]` reader reads
/// one, every key at the table's place in the file (an inline table's keys keep no spans of
/// their own).
fn inline_material(
    ctx: &mut Ctx,
    m: &S<MaterialRef>,
    p: &super::raw::PlainMaterial,
    named: &BTreeMap<String, Mat>,
) -> Result<Mat, Error> {
    let sp = |v: &Option<Vec<f32>>| v.clone().map(|v| Spanned::new(m.span(), v));
    let spf = |v: Option<f32>| v.map(|v| Spanned::new(m.span(), v));
    fn at<T>(span: std::ops::Range<usize>, v: Option<T>) -> Option<S<T>> {
        v.map(|v| Spanned::new(span, v))
    }
    let raw = RawMaterial {
        base: p.base.clone().map(|b| Spanned::new(m.span(), b)),
        paint: sp(&p.paint),
        ambient: sp(&p.ambient),
        diffuse: sp(&p.diffuse),
        specular: sp(&p.specular),
        emission: sp(&p.emission),
        shininess: spf(p.shininess),
        alpha: spf(p.alpha),
        diffuse_map: at(m.span(), p.diffuse_map.clone()),
        ambient_map: at(m.span(), p.ambient_map.clone()),
        specular_map: at(m.span(), p.specular_map.clone()),
        emission_map: at(m.span(), p.emission_map.clone()),
        shininess_map: at(m.span(), p.shininess_map.clone()),
        alpha_map: at(m.span(), p.alpha_map.clone()),
        normal_map: at(m.span(), p.normal_map.clone()),
        bump_map: at(m.span(), p.bump_map.clone()),
        bump_scale: at(m.span(), p.bump_scale),
        uv_scale: at(m.span(), p.uv_scale.clone()),
        uv_offset: at(m.span(), p.uv_offset.clone()),
        wrap: at(m.span(), p.wrap.clone()),
        filter: at(m.span(), p.filter.clone()),
        encoding: at(m.span(), p.encoding.clone()),
        alpha_cutoff: at(m.span(), p.alpha_cutoff),
        blend: at(m.span(), p.blend),
        normal_scale: at(m.span(), p.normal_scale),
        normal_green: at(m.span(), p.normal_green.clone()),
    };
    material(ctx, &raw, "material", named)
}

/// A `shape` object: the primitive with its segments checked against the limits, its normals
/// as asked, its material and maps.
fn shape_object(
    ctx: &mut Ctx,
    o: &RawObject,
    span: std::ops::Range<usize>,
    shape: &S<String>,
    world_from_object: Mat4,
    material: Option<Mat>,
    shading: ShadingSettings,
) -> Result<Vec<Object>, Error> {
    let crease = crease(ctx, o)?;
    let apply_normals = |mesh: Mesh, default: &str, allowed: &[&str]| -> Result<Mesh, Error> {
        let choice = match o.normals.as_ref() {
            Some(n) => ctx.name(n, "normals", allowed)?,
            None => default,
        };
        Ok(with_normals(mesh, choice, crease))
    };
    let kind = ctx.name(shape, "shape", SHAPES)?;
    let default_segments = match kind {
        "plane" => 1,
        "teapot" => 10,
        _ => 64,
    };
    let min = if matches!(kind, "plane" | "teapot") { 1 } else { 3 };
    let segments = match &o.segments {
        Some(s) => ctx.int(s, "segments", min, i64::from(MAX_SEGMENTS))? as u32,
        None => default_segments,
    };
    let n = u64::from(segments);
    let triangles = match kind {
        "teapot" => 64 * n * n,
        "plane" => 2 * n * n,
        "cube" => 12,
        _ => n * n + 4 * n,
    };
    if triangles > phong_core::limits::MAX_PRIMITIVE_TRIANGLES {
        let span = o.segments.as_ref().map_or(span.clone(), |s| s.span());
        return ctx.err(
            &span,
            "segments",
            format!(
                "a {kind} with {segments} segments has about {triangles} triangles; the limit is {}",
                phong_core::limits::MAX_PRIMITIVE_TRIANGLES
            ),
        );
    }
    ctx.add_triangles(
        triangles,
        &o.segments.as_ref().map_or(span.clone(), |s| s.span()),
        "segments",
    )?;
    if kind != "torus" {
        for (v, key) in [(&o.radius, "radius"), (&o.tube, "tube")] {
            if let Some(v) = v {
                return ctx.err(&v.span(), key, format!("only a torus has `{key}`; use `scale`"));
            }
        }
    }
    let mesh = match kind {
        "sphere" => primitives::sphere(segments),
        "torus" => {
            let r = match &o.radius {
                Some(r) => ctx.num(r, "radius", |x| x > 0.0, "> 0")?,
                None => 1.0,
            };
            let t = match &o.tube {
                Some(t) => ctx.num(t, "tube", |x| x > 0.0, "> 0")?,
                None => 0.25,
            };
            primitives::torus(segments, r, t)
        }
        "cylinder" => primitives::cylinder(segments),
        "cone" => primitives::cone(segments),
        "cube" => primitives::cube(),
        "plane" => primitives::plane(segments),
        _ => primitives::teapot(segments),
    };
    if let Some(f) = &o.fit {
        return ctx.err(&f.span(), "fit", "only a mesh has `fit`; a shape is already unit-sized");
    }
    let mesh = apply_normals(mesh, "analytic", &["analytic", "flat", "smooth", "angle"])?;
    let (material, maps) = material.unwrap_or_default();
    let mesh = tangents_for(mesh, &maps);
    Ok(vec![Object {
        name: kind.to_string(),
        mesh: mesh.into_transformed(&world_from_object),
        material,
        shading,
        maps,
    }])
}

/// The normals a part is drawn with where the scene does not ask: the file's where every
/// vertex has a usable one, else [`computed_normals`].
pub(crate) fn default_normals(p: &ModelPart) -> &'static str {
    if p.has_normals && !p.mesh.normals().contains(&Vec3::ZERO) {
        "file"
    } else {
        computed_normals(p)
    }
}

/// The normals computed for a part whose file normals are missing or unusable: flat where its
/// format asks for them when it has none (glTF), else by angle.
fn computed_normals(p: &ModelPart) -> &'static str {
    if !p.has_normals && p.flat_without_normals {
        "flat"
    } else {
        "angle"
    }
}

/// A part's mesh as its object draws it: fitted to `fit_frame` (centre and radius, where the
/// object has `fit`) and given the normals of `choice` (`crease` degrees for `"angle"`).
pub(crate) fn drawn_mesh(
    mesh: &Mesh,
    fit_frame: Option<(glam::DVec3, f64)>,
    choice: &str,
    crease: f32,
) -> Result<Mesh, phong_core::Error> {
    if choice == "angle" {
        // New arrays either way: the positions fitted straight into them, the mesh's own
        // normals not copied.
        return crate::timing::timed(
            |t| &mut t.normals,
            || match fit_frame {
                Some(frame) => mesh.crease_normals_mapped(fit_map(frame), crease),
                None => mesh.crease_normals_mapped(|p| p, crease),
            },
        );
    }
    Ok(with_normals(fitted(mesh.clone(), fit_frame)?, choice, crease))
}

/// A position moved into the frame of `centre` and `radius`: in f64 (coordinates near f32's
/// largest, a radius whose inverse is below its smallest normal number). A uniform scale and
/// a move: the file's normals keep their directions.
fn fit_map((centre, radius): (glam::DVec3, f64)) -> impl Fn(Vec3) -> Vec3 {
    move |x| ((x.as_dvec3() - centre) / radius).as_vec3()
}

/// `mesh` fitted to `fit_frame` (centre and radius), where given.
fn fitted(mut mesh: Mesh, fit_frame: Option<(glam::DVec3, f64)>) -> Result<Mesh, phong_core::Error> {
    if let Some(frame) = fit_frame {
        // Fitted before the normals are computed (at 1e30, f32 cross products overflow).
        mesh = mesh.with_positions_mapped(fit_map(frame))?;
    }
    Ok(mesh)
}

/// `mesh` with the normals of `choice` (`"flat"`, `"smooth"`, `"angle"` at `crease` degrees;
/// anything else keeps its own), timed as the load's `normals` stage.
fn with_normals(mesh: Mesh, choice: &str, crease: f32) -> Mesh {
    crate::timing::timed(
        |t| &mut t.normals,
        || match choice {
            "flat" => mesh.with_flat_normals(),
            "smooth" => mesh.with_smooth_normals(),
            "angle" => mesh.into_crease_normals(crease),
            _ => mesh,
        },
    )
}

/// A `mesh` object: one object a part of the model file, placed in the file's coordinates (or
/// fitted), its normals as asked (the file's where usable), the scene's material or the file's.
fn mesh_objects(
    ctx: &mut Ctx,
    o: &RawObject,
    m: &S<String>,
    world_from_object: Mat4,
    material: Option<Mat>,
    shading: ShadingSettings,
) -> Result<Vec<Object>, Error> {
    let crease = crease(ctx, o)?;
    let normals_choice = o.normals.as_ref();
    if let Some(s) = &o.segments {
        return ctx.err(&s.span(), "segments", "a mesh has no `segments`");
    }
    let mut warnings = Vec::new();
    let mut sources = Vec::new();
    let fit = o.fit.as_ref().is_some_and(|f| *f.get_ref());
    let parts = match ctx.meshes {
        Some(lookup) => match lookup(m.get_ref()) {
            Ok(parts) => parts,
            Err(msg) => return ctx.err(&m.span(), "mesh", msg),
        },
        None => {
            let file = ctx.path.parent().unwrap_or(Path::new("")).join(m.get_ref());
            if !file.exists() {
                return ctx.err(&m.span(), "mesh", format!("file not found: {}", file.display()));
            }
            // A file in no format phong reads is reported at the scene's `mesh` key.
            match ModelFile::read(&file) {
                Err(e @ Error::Model { .. }) => return ctx.err(&m.span(), "mesh", e.to_string()),
                r => {
                    let model = r?;
                    warnings.extend(model.warnings);
                    sources.extend(model.sources);
                    model.parts
                }
            }
        }
    };
    // The file's coordinates (the re-centred model moved back to where the file puts
    // it), or with `fit` the model centred at the origin with a bounding sphere of
    // radius 1, before the object's own transform. A fitted model is fitted before its
    // normals are computed (at 1e30, f32 cross products overflow).
    let (fit_frame, world_from_file) = match crate::framing::fit_of(&parts) {
        Some(frame) if fit => (Some(frame), world_from_object),
        _ => match parts.first() {
            Some(p) if p.origin != glam::DVec3::ZERO => {
                (None, world_from_object * Mat4::from_translation(p.origin.as_vec3()))
            }
            _ => (None, world_from_object),
        },
    };
    let mut out = Vec::new();
    for mut p in parts {
        // File normals where every vertex has a usable one; else, or where `"file"`
        // is asked of a model without them, computed normals (`computed_normals`), with a
        // warning.
        let bad = p.mesh.normals().iter().filter(|n| **n == Vec3::ZERO).count();
        let usable = default_normals(&p) == "file";
        let asked = normals_choice
            .map(|n| ctx.name(n, "normals", &["file", "flat", "smooth", "angle"]))
            .transpose()?;
        if p.has_normals && bad > 0 && asked.is_none_or(|a| a == "file") {
            warnings.push(format!(
                "{}: {bad} of its {} file normals are zero or not finite: normals computed by angle instead",
                p.name,
                p.mesh.normals().len()
            ));
        } else if !p.has_normals && asked == Some("file") {
            warnings.push(format!(
                "{}: `normals = \"file\"` but the file has no normals for it: normals computed {}",
                p.name,
                if computed_normals(&p) == "flat" {
                    "flat"
                } else {
                    "by angle"
                }
            ));
        }
        let choice = match asked {
            Some("file") if !usable => computed_normals(&p),
            Some(a) => a,
            None => default_normals(&p),
        };
        let model_error = |e: phong_core::Error| Error::Model {
            path: ctx.path.to_path_buf(),
            message: format!("{}: {e}", p.name),
        };
        // Flat normals are made with the placement below (one pass), unless tangents need
        // them first.
        let mut flat = false;
        let mesh = match p.drawn.take() {
            // Computed beside the model-alone scene's framing by this same function, for the
            // choice and crease it would be given here.
            Some(drawn) if fit && asked.is_none() && o.crease.is_none() => drawn,
            _ => {
                let mesh = std::mem::take(&mut p.mesh);
                // The framing's fitted vertices where it made them (the same values).
                let mesh = match p.fitted.take() {
                    Some(points) if fit_frame.is_some() => mesh.with_positions(points),
                    _ => fitted(mesh, fit_frame),
                }
                .map_err(model_error)?;
                flat = choice == "flat";
                // Flat normals are made with the placement below.
                if flat { mesh } else { with_normals(mesh, choice, crease) }
            }
        };
        // The scene's material replaces the file's, maps and all.
        let (material, maps) = material.clone().unwrap_or((p.material.unwrap_or_default(), p.maps));
        // (Flat normals give each triangle's corners their coordinates: none without triangles.)
        let has_uvs = mesh.has_uvs() && !(flat && mesh.triangles().is_empty());
        let maps = if !maps.is_empty() && !has_uvs {
            warnings.push(format!(
                "{}: its material has texture maps but the model has no texture coordinates: maps not used",
                p.name
            ));
            Maps {
                blend: maps.blend,
                ..Maps::default()
            }
        } else {
            maps
        };
        let mesh = if flat && maps.normal.is_none() {
            crate::timing::timed(
                |t| &mut t.normals,
                || mesh.flat_transformed(&world_from_file, &crate::beside::Beside),
            )
        } else {
            let mesh = if flat { with_normals(mesh, "flat", crease) } else { mesh };
            tangents_for(mesh, &maps).into_transformed(&world_from_file)
        };
        out.push(Object {
            name: p.name,
            mesh,
            material,
            shading,
            maps,
        });
    }
    let tris: u64 = out.iter().map(|o| o.mesh.triangles().len() as u64).sum();
    ctx.warnings.extend(warnings);
    ctx.sources.extend(sources);
    ctx.add_triangles(tris, &m.span(), "mesh")?;
    Ok(out)
}

/// The mesh with MikkTSpace tangents where a normal map needs them (after its normals, which
/// they are computed from) and it has none of its own (a glTF's `TANGENT`, kept with the file's
/// normals).
fn tangents_for(mesh: Mesh, maps: &Maps) -> Mesh {
    if maps.normal.is_some() && mesh.has_uvs() && mesh.tangents().is_empty() {
        mesh.with_mikktspace_tangents()
    } else {
        mesh
    }
}

/// `world_from_object = T · Rz · Ry · Rx · S`: scale, then rotate about x, y, z (degrees), then move.
pub(super) fn transform(ctx: &Ctx, o: &RawObject) -> Result<Mat4, Error> {
    let t = o
        .position
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |p| ctx.vec3(p, "position"))?;
    let r = o
        .rotation
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |p| ctx.vec3(p, "rotation"))?;
    let s = match &o.scale {
        None => Vec3::ONE,
        Some(sc) => {
            let v = match sc.get_ref() {
                Scale::Uniform(k) => Vec3::splat(*k),
                Scale::Axes(v) if v.len() == 3 => Vec3::new(v[0], v[1], v[2]),
                Scale::Axes(_) => return ctx.err(&sc.span(), "scale", "expected a number or [x, y, z]"),
            };
            if !v.is_finite() || v.cmpeq(Vec3::ZERO).any() {
                return ctx.err(&sc.span(), "scale", "must be finite and non-zero");
            }
            v
        }
    };
    let q = Quat::from_euler(EulerRot::ZYX, r.z.to_radians(), r.y.to_radians(), r.x.to_radians());
    Ok(Mat4::from_scale_rotation_translation(s, q, t))
}
