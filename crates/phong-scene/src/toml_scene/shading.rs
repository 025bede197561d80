//! `[shading]`: the scene's shading settings, which every object starts from.

use super::choices::{INTERPOLATIONS, LYON_LAMBDAS, MODELS, Model, NORMALIZATIONS, OUTPUTS, VIEWERS, apply_model};
use super::ctx::Ctx;
use super::raw::RawShading;
use crate::Error;
use phong_core::{Camera, Interpolation, LyonLambda, Normalization, Output, ShadingOptions, ShadingSettings};

pub(super) fn shading(ctx: &Ctx, r: Option<&RawShading>, camera: &Camera) -> Result<ShadingSettings, Error> {
    let mut options = ShadingOptions::default();
    let mut s = ShadingSettings {
        options,
        interpolation: Interpolation::Phong,
        viewer: camera.default_viewer(),
        output: Output::Color,
    };
    let Some(r) = r else { return Ok(s) };
    options.two_sided = r.two_sided.unwrap_or(false);
    options.gate_specular = r.gate_specular.unwrap_or(true);
    options.clamp = r.clamp.unwrap_or(true);
    if let Some(n) = &r.normalization {
        options.normalization = ctx.choice(n, "normalization", NORMALIZATIONS)?;
    }
    let squarings = match &r.lyon_squarings {
        Some(n) => ctx.int(n, "lyon_squarings", 0, 16)? as u32,
        None => 3,
    };
    let lambda = match &r.lyon_lambda {
        Some(l) => ctx.choice(l, "lyon_lambda", LYON_LAMBDAS)?,
        None => LyonLambda::Dot,
    };
    let model = match &r.model {
        Some(m) => ctx.choice(m, "model", MODELS)?,
        None => Model::BlinnPhong,
    };
    if model == Model::OpenGl {
        for (set, key) in [(
            r.normalization
                .as_ref()
                .map(|n| n.span())
                .filter(|_| options.normalization != Normalization::None),
            "normalization",
        )] {
            if let Some(span) = set {
                return ctx.err(&span, key, "the \"opengl\" model has no normalization");
            }
        }
        if r.clamp == Some(false) || r.gate_specular == Some(false) {
            let span = r.model.as_ref().map_or(0..0, |m| m.span());
            return ctx.err(
                &span,
                "model",
                "the \"opengl\" model always clamps and gates the specular term",
            );
        }
    }
    apply_model(&mut options, model, (squarings, lambda));
    s.options = options;
    if let Some(i) = &r.interpolation {
        s.interpolation = ctx.choice(i, "interpolation", INTERPOLATIONS)?;
    }
    if let Some(v) = &r.viewer {
        s.viewer = ctx.choice(v, "viewer", VIEWERS)?;
    }
    if let Some(o) = &r.output {
        s.output = ctx.choice(o, "output", OUTPUTS)?;
    }
    Ok(s)
}
