//! Materials: a name from the table, a `[materials]` entry, or an inline table.

use super::ctx::{Ctx, S};
use super::raw::RawMaterial;
use crate::Error;
use phong_core::{Color, Material, nearest_names, normalize_name};
use std::collections::BTreeMap;

pub(super) fn material(
    ctx: &Ctx,
    m: &RawMaterial,
    key: &str,
    named: &BTreeMap<String, Material>,
) -> Result<Material, Error> {
    let start = match &m.base {
        Some(b) => lookup_material(ctx, b, named)?,
        None => match &m.paint {
            Some(_) => Material::paint(Color::BLACK, 0.0).expect("valid"),
            None => Material::default(),
        },
    };
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
    let _ = key;
    Ok(Material::new(ambient, diffuse, specular, emission, shininess)
        .and_then(|m| m.with_alpha(alpha))
        .expect("checked values"))
}

pub(super) fn lookup_material(
    ctx: &Ctx,
    name: &S<String>,
    named: &BTreeMap<String, Material>,
) -> Result<Material, Error> {
    if let Some(m) = named.get(&normalize_name(name.get_ref())) {
        return Ok(*m);
    }
    Material::named(name.get_ref()).or_else(|_| {
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
