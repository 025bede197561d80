//! The override rules: what an object's `model`, `interpolation` and `output` keys do to the
//! scene's `[shading]`, and what `phong render`'s flags of the same names do to every object.
//! One owner, so that the file and the command line cannot disagree.

use crate::toml_scene::{Model, apply_model};
use phong_core::{Interpolation, LyonLambda, Output, Scene, ShadingSettings, SpecularModel};

/// Overrides of shading settings; `None` keeps what is there.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Overrides {
    /// The shading model; Lyon's parameters are kept where the settings are Lyon's, else
    /// Lyon's defaults (3 squarings, `λ = N·H`-style dot).
    pub model: Option<Model>,
    /// Flat, Gouraud or Phong.
    pub interpolation: Option<Interpolation>,
    /// The term shown.
    pub output: Option<Output>,
}

impl Overrides {
    /// Applies the overrides to `settings`.
    pub fn apply(&self, settings: &mut ShadingSettings) {
        if let Some(model) = self.model {
            let lyon = match settings.options.specular {
                SpecularModel::Lyon { squarings, lambda } => (squarings, lambda),
                _ => (3, LyonLambda::Dot),
            };
            apply_model(&mut settings.options, model, lyon);
        }
        if let Some(i) = self.interpolation {
            settings.interpolation = i;
        }
        if let Some(o) = self.output {
            settings.output = o;
        }
    }

    /// Applies the overrides to every object of `scene`.
    pub fn apply_to_scene(&self, scene: &mut Scene) {
        for o in &mut scene.objects {
            self.apply(&mut o.shading);
        }
    }
}
