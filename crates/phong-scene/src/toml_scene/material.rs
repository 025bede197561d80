//! Materials: a name from the table, a `[materials]` entry, or an inline table; with their
//! texture maps (paths relative to the scene file).

use super::ctx::{Ctx, S};
use super::raw::RawMaterial;
use crate::Error;
use crate::texture_file::{MapRequest, Slot, Source, resolve};
use glam::Vec2;
use phong_core::{Color, Maps, Material, Sampler, UvTransform, Wrap, nearest_names, normalize_name};
use std::collections::BTreeMap;

/// A material with its maps.
pub(super) type Mat = (Material, Maps);

pub(super) fn material(ctx: &mut Ctx, m: &RawMaterial, key: &str, named: &BTreeMap<String, Mat>) -> Result<Mat, Error> {
    let (start, base_maps) = match &m.base {
        Some(b) => lookup_material(ctx, b, named)?,
        None => (
            match &m.paint {
                Some(_) => Material::paint(Color::BLACK, 0.0).expect("valid"),
                None => Material::default(),
            },
            Maps::default(),
        ),
    };
    let material = colours(ctx, m, start)?;
    let maps = maps(ctx, m, key, base_maps)?;
    Ok((material, maps))
}

/// The material's colours, shininess and alpha over `start` (its base).
fn colours(ctx: &Ctx, m: &RawMaterial, start: Material) -> Result<Material, Error> {
    let paint = ctx.opt_color(&m.paint, "paint")?;
    let ambient = ctx
        .opt_color(&m.ambient, "ambient")?
        .or(paint)
        .unwrap_or(start.ambient());
    let diffuse = ctx
        .opt_color(&m.diffuse, "diffuse")?
        .or(paint)
        .unwrap_or(start.diffuse());
    let specular = ctx.opt_color(&m.specular, "specular")?.unwrap_or(start.specular());
    let emission = ctx.opt_color(&m.emission, "emission")?.unwrap_or(start.emission());
    let shininess = match &m.shininess {
        Some(s) => ctx.num(s, "shininess", |x| x >= 0.0, ">= 0")?,
        None => start.shininess(),
    };
    let alpha = match &m.alpha {
        Some(a) => ctx.num(a, "alpha", |x| (0.0..=1.0).contains(&x), "in [0, 1]")?,
        None => start.alpha(),
    };
    Ok(Material::new(ambient, diffuse, specular, emission, shininess)
        .and_then(|m| m.with_alpha(alpha))
        .expect("checked values"))
}

/// The material's maps over `base` (its base material's): each `*_map` key read from the file
/// it names, with the sampler, coordinates and encoding keys. An image that is missing or
/// cannot be decoded is a warning and the map is left out.
fn maps(ctx: &mut Ctx, m: &RawMaterial, key: &str, base: Maps) -> Result<Maps, Error> {
    let wrap = match &m.wrap {
        Some(w) => ctx.choice(
            w,
            "wrap",
            &[
                ("repeat", Wrap::Repeat),
                ("clamp", Wrap::Clamp),
                ("mirror", Wrap::Mirror),
            ],
        )?,
        None => Wrap::Repeat,
    };
    let sampler = match &m.filter {
        Some(f) => ctx.choice(
            f,
            "filter",
            &[
                ("trilinear", Sampler::trilinear(wrap)),
                ("bilinear", Sampler::bilinear(wrap)),
                ("nearest", Sampler::nearest(wrap)),
            ],
        )?,
        None => Sampler::trilinear(wrap),
    };
    let srgb = match &m.encoding {
        Some(e) => ctx.choice(e, "encoding", &[("linear", false), ("srgb", true)])?,
        None => false,
    };
    let pair = |ctx: &Ctx, v: &Option<S<Vec<f32>>>, k: &str, default: f32| -> Result<Vec2, Error> {
        match v {
            None => Ok(Vec2::splat(default)),
            Some(s) => match s.get_ref().as_slice() {
                [u, v] if u.is_finite() && v.is_finite() => Ok(Vec2::new(*u, *v)),
                _ => ctx.err(&s.span(), k, "expected 2 finite numbers [u, v]"),
            },
        }
    };
    let scale = pair(ctx, &m.uv_scale, "uv_scale", 1.0)?;
    let offset = pair(ctx, &m.uv_offset, "uv_offset", 0.0)?;
    let bump_scale = match &m.bump_scale {
        Some(b) => ctx.num(b, "bump_scale", f32::is_finite, "finite")?,
        None => 1.0,
    };
    let normal_scale = match &m.normal_scale {
        Some(s) => ctx.num(s, "normal_scale", f32::is_finite, "finite")?,
        None => 1.0,
    };
    let green_down = match &m.normal_green {
        Some(g) => ctx.choice(g, "normal_green", &[("up", false), ("down", true)])?,
        None => false,
    };
    let alpha_cutoff = match &m.alpha_cutoff {
        Some(a) => Some(ctx.num(a, "alpha_cutoff", |x| (0.0..=1.0).contains(&x), "in [0, 1]")?),
        None => None,
    };
    let keys = [
        (&m.diffuse_map, Slot::Diffuse, "diffuse_map"),
        (&m.ambient_map, Slot::Ambient, "ambient_map"),
        (&m.specular_map, Slot::Specular, "specular_map"),
        (&m.emission_map, Slot::Emission, "emission_map"),
        (&m.shininess_map, Slot::Shininess, "shininess_map"),
        (&m.alpha_map, Slot::Alpha, "alpha_map"),
        (&m.normal_map, Slot::Normal, "normal_map"),
        (&m.bump_map, Slot::Bump, "bump_map"),
    ];
    let mut requests = Vec::new();
    for (file, slot, k) in keys {
        let Some(file) = file else { continue };
        let (line, _) = crate::error::line_col(ctx.src, file.span().start);
        requests.push(MapRequest {
            slot,
            source: Source::File(file.get_ref().clone()),
            transform: UvTransform::scale_offset(scale, offset),
            sampler,
            channel: None,
            srgb,
            at: format!("{}:{line}: `{k}`", ctx.path.display()),
            scale: if slot == Slot::Bump { bump_scale } else { normal_scale },
            green_down,
            set: 0,
        });
    }
    let dir = ctx.path.parent().unwrap_or(std::path::Path::new("")).to_path_buf();
    let server = !ctx.files;
    let read = |name: &str| -> Result<Vec<u8>, String> {
        if server {
            return Err("a scene sent to phong serve names no files (upload an OBJ with its MTL and images)".into());
        }
        let p = dir.join(name);
        crate::read_bounded(&p, phong_core::limits::MAX_IMAGE_FILE_BYTES, "texture image").map_err(|e| match e {
            Error::Read { source, .. } => format!("cannot read {}: {source}", p.display()),
            other => other.to_string(),
        })
    };
    let mut warnings = Vec::new();
    let name = key.strip_prefix("materials.").unwrap_or(key);
    let mine = resolve(&requests, name, &read, &mut ctx.textures, &mut warnings);
    ctx.warnings.extend(warnings);
    for r in &requests {
        if let Source::File(f) = &r.source {
            ctx.sources.push(dir.join(f));
        }
    }
    let mut out = base;
    for (slot, map) in [
        (&mut out.diffuse, mine.diffuse),
        (&mut out.ambient, mine.ambient),
        (&mut out.specular, mine.specular),
        (&mut out.emission, mine.emission),
    ] {
        if map.is_some() {
            *slot = map;
        }
    }
    if mine.shininess.is_some() {
        out.shininess = mine.shininess;
    }
    if mine.alpha.is_some() {
        out.alpha = mine.alpha;
    }
    if mine.normal.is_some() {
        out.normal = mine.normal;
    }
    out.alpha_cutoff = alpha_cutoff.or(mine.alpha_cutoff).or(out.alpha_cutoff);
    if let Some(b) = &m.blend {
        out.blend = *b.get_ref();
    }
    Ok(out)
}

pub(super) fn lookup_material(ctx: &Ctx, name: &S<String>, named: &BTreeMap<String, Mat>) -> Result<Mat, Error> {
    if let Some(m) = named.get(&normalize_name(name.get_ref())) {
        return Ok(m.clone());
    }
    Material::named(name.get_ref())
        .map(|m| (m, Maps::default()))
        .or_else(|_| {
            let all: Vec<&str> = named
                .keys()
                .map(String::as_str)
                .chain(phong_core::named_materials().iter().map(|m| m.name))
                .collect();
            let near = nearest_names(name.get_ref(), all.iter().copied());
            let hint = if near.is_empty() {
                "; `phong materials` lists the built-in ones".to_string()
            } else {
                format!("; did you mean {}?", near.join(" or "))
            };
            ctx.err(
                &name.span(),
                "material",
                format!("unknown material \"{}\"{hint}", name.get_ref()),
            )
        })
}
