//! The names a scene's keys accept (and `phong render`'s flags of the same names), and how a
//! model name becomes shading options.

use phong_core::{
    Encoding, Interpolation, LyonLambda, Normalization, Output, ShadingOptions, SpecularModel, Viewer, nearest_names,
};

/// The shading models of the `model` key and `--model`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    /// No specular term.
    Lambert,
    /// Phong's `(R·V)^s`.
    Phong,
    /// Blinn-Phong's `(N·H)^s`.
    BlinnPhong,
    /// Lyon's approximation of Phong.
    PhongLyon,
    /// OpenGL 2.1 fixed function.
    OpenGl,
}

/// `model` values.
pub const MODELS: &[(&str, Model)] = &[
    ("lambert", Model::Lambert),
    ("phong", Model::Phong),
    ("blinn-phong", Model::BlinnPhong),
    ("phong-lyon", Model::PhongLyon),
    ("opengl", Model::OpenGl),
];
/// `interpolation` values.
pub const INTERPOLATIONS: &[(&str, Interpolation)] = &[
    ("flat", Interpolation::Flat),
    ("gouraud", Interpolation::Gouraud),
    ("phong", Interpolation::Phong),
];
/// `output` values.
pub const OUTPUTS: &[(&str, Output)] = &[
    ("color", Output::Color),
    ("ambient", Output::Ambient),
    ("diffuse", Output::Diffuse),
    ("specular", Output::Specular),
    ("normal", Output::Normal),
    ("depth", Output::Depth),
];
pub(crate) const NORMALIZATIONS: &[(&str, Normalization)] = &[
    ("none", Normalization::None),
    ("phong", Normalization::Phong),
    ("blinn-phong", Normalization::BlinnPhong),
    ("blinn-phong-exact", Normalization::BlinnPhongExact),
];
pub(crate) const VIEWERS: &[(&str, Viewer)] = &[("local", Viewer::Local), ("infinite", Viewer::Infinite)];
pub(crate) const ENCODINGS: &[(&str, Encoding)] = &[("linear", Encoding::Linear), ("srgb", Encoding::Srgb)];
pub(crate) const PROJECTIONS: &[&str] = &["perspective", "orthographic"];
pub(crate) const LIGHT_TYPES: &[&str] = &["directional", "point", "spot"];
pub(crate) const SHAPES: &[&str] = &["sphere", "torus", "cylinder", "cone", "cube", "plane", "teapot"];
pub(crate) const LYON_LAMBDAS: &[(&str, LyonLambda)] =
    &[("dot", LyonLambda::Dot), ("difference", LyonLambda::Difference)];

/// Looks `value` up in `table`; the error lists the choices and the nearest ones.
pub fn parse_choice<T: Copy>(key: &str, value: &str, table: &[(&str, T)]) -> Result<T, String> {
    if let Some((_, v)) = table.iter().find(|(n, _)| *n == value) {
        return Ok(*v);
    }
    let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
    let near = nearest_names(value, names.iter().copied());
    let hint = if near.is_empty() {
        String::new()
    } else {
        format!(
            " (did you mean {}?)",
            near.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(" or ")
        )
    };
    Err(format!(
        "unknown {key} \"{value}\"{hint}; expected one of {}",
        names.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(", ")
    ))
}

/// Sets `options` for `model` (`opengl`: the OpenGL preset, keeping `two_sided`).
pub fn apply_model(options: &mut ShadingOptions, model: Model, lyon: (u32, LyonLambda)) {
    options.specular = match model {
        Model::Lambert => SpecularModel::None,
        Model::Phong => SpecularModel::Phong,
        Model::BlinnPhong | Model::OpenGl => SpecularModel::BlinnPhong,
        Model::PhongLyon => SpecularModel::Lyon {
            squarings: lyon.0,
            lambda: lyon.1,
        },
    };
    if model == Model::OpenGl {
        *options = ShadingOptions::opengl(options.two_sided);
    }
}
