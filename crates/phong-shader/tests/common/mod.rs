//! The scenes the shader tests draw: every model, each interpolation, an option each, both
//! cameras, both encodings, three kinds of light.

use phong_core::Scene;

const MODELS: [&str; 5] = ["phong", "blinn-phong", "lambert", "phong-lyon", "opengl"];

/// A scene of a sphere and a torus under `shading` (TOML keys) and three kinds of light.
fn scene(shading: &str, camera: &str, encoding: &str) -> Scene {
    let text = format!(
        "[image]\nwidth = 160\nheight = 120\nbackground = [0.05, 0.05, 0.07]\nencoding = \"{encoding}\"\n\n{camera}\n\
         [shading]\n{shading}\nambient = [0.2, 0.2, 0.2]\n\n\
         [[light]]\ntype = \"directional\"\ndirection = [-1.0, -1.0, -1.5]\ncolor = [0.6, 0.6, 0.6]\n\
         [[light]]\ntype = \"point\"\nposition = [2.0, 2.0, 3.0]\nattenuation = [1.0, 0.05, 0.01]\n\
         [[light]]\ntype = \"spot\"\nposition = [0.0, 3.0, 3.0]\ndirection = [0.0, -1.0, -1.0]\ncutoff = 40.0\nexponent = 4.0\n\n\
         [[object]]\nshape = \"sphere\"\nmaterial = \"gold\"\nposition = [-0.6, 0.0, 0.0]\nscale = 0.8\n\n\
         [[object]]\nshape = \"torus\"\nmaterial = \"jade\"\nposition = [0.8, 0.0, -0.5]\nrotation = [60.0, 0.0, 0.0]\nscale = 0.6\n"
    );
    phong_scene::parse_scene(&text, std::path::Path::new("shader.toml"))
        .expect("the scene")
        .scene
}

/// The scenes, each with its `[shading]` keys (for messages).
pub fn scenes() -> Vec<(String, Scene)> {
    let perspective = "[camera]\nposition = [0.5, 1.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 45.0\n";
    let orthographic = "[camera]\nprojection = \"orthographic\"\nposition = [0.0, 0.0, 10.0]\nheight = 3.2\n";
    let mut out = Vec::new();
    for (k, model) in MODELS.iter().enumerate() {
        for interp in ["phong", "gouraud", "flat"] {
            let extra = match k % 3 {
                0 => "two_sided = true",
                1 if *model != "opengl" => "normalization = \"blinn-phong\"\noutput = \"specular\"",
                _ => "viewer = \"infinite\"",
            };
            let shading = format!("model = \"{model}\"\ninterpolation = \"{interp}\"\n{extra}");
            let camera = if k % 2 == 0 { perspective } else { orthographic };
            let encoding = if interp == "gouraud" { "srgb" } else { "linear" };
            out.push((shading.clone(), scene(&shading, camera, encoding)));
        }
    }
    out
}
