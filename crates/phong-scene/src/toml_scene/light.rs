//! `[[light]]`: directional, point and spot lights.

use super::choices::LIGHT_TYPES;
use super::ctx::{Ctx, S};
use super::raw::RawLight;
use crate::Error;
use phong_core::{Attenuation, Color, Light, LightColor};

pub(super) fn light(ctx: &Ctx, l: &S<RawLight>) -> Result<Light, Error> {
    let span = l.span();
    let l = l.get_ref();
    let kind = ctx.name(&l.kind, "type", LIGHT_TYPES)?;
    let base = ctx.opt_color(&l.color, "color")?.unwrap_or(Color::WHITE);
    let colors = LightColor::new(
        ctx.opt_color(&l.ambient, "ambient")?.unwrap_or(Color::BLACK),
        ctx.opt_color(&l.diffuse, "diffuse")?.unwrap_or(base),
        ctx.opt_color(&l.specular, "specular")?.unwrap_or(base),
    )
    .expect("checked colours");
    let attenuation = match &l.attenuation {
        Some(a) => {
            let v = a.get_ref();
            if v.len() != 3 {
                return ctx.err(
                    &a.span(),
                    "attenuation",
                    "expected 3 numbers [constant, linear, quadratic]",
                );
            }
            Attenuation::new(v[0], v[1], v[2]).or_else(|e| ctx.err(&a.span(), "attenuation", e.to_string()))?
        }
        None => Attenuation::NONE,
    };
    let need = |s: &Option<S<Vec<f32>>>, key: &str| match s {
        Some(s) => ctx.vec3(s, key),
        None => ctx.err(&span, key, format!("a {kind} light needs `{key}`")),
    };
    let reject = |present: bool, key: &str| {
        if present {
            ctx.err(&span, key, format!("a {kind} light has no `{key}`"))
        } else {
            Ok(())
        }
    };
    let dir_err = |s: &Option<S<Vec<f32>>>, e: phong_core::Error| {
        ctx.err(
            &s.as_ref().map_or(span.clone(), |s| s.span()),
            "direction",
            e.to_string(),
        )
    };
    match kind {
        "directional" => {
            reject(l.position.is_some(), "position")?;
            reject(l.attenuation.is_some(), "attenuation")?;
            reject(l.cutoff.is_some(), "cutoff")?;
            reject(l.exponent.is_some(), "exponent")?;
            Light::directional(need(&l.direction, "direction")?, colors).or_else(|e| dir_err(&l.direction, e))
        }
        "point" => {
            reject(l.direction.is_some(), "direction")?;
            reject(l.cutoff.is_some(), "cutoff")?;
            reject(l.exponent.is_some(), "exponent")?;
            Ok(Light::point(need(&l.position, "position")?, colors, attenuation).expect("checked position"))
        }
        _ => {
            let cutoff = match &l.cutoff {
                Some(c) => ctx.num(c, "cutoff", |x| (0.0..=90.0).contains(&x), "in [0, 90] degrees")?,
                None => return ctx.err(&span, "cutoff", "a spot light needs `cutoff` (degrees, 0 to 90)"),
            };
            let exponent = match &l.exponent {
                Some(e) => ctx.num(e, "exponent", |x| x >= 0.0, ">= 0")?,
                None => 0.0,
            };
            let direction = need(&l.direction, "direction")?;
            Light::spot(
                need(&l.position, "position")?,
                direction,
                cutoff,
                exponent,
                colors,
                attenuation,
            )
            .or_else(|e| dir_err(&l.direction, e))
        }
    }
}
