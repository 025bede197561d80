//! The standalone WebGL2 page: the scene's meshes embedded, drawn with the exported GLSL ES
//! 3.00 shaders and the scene's camera at the scene's image size. No network, no library.

use crate::{Unsupported, Version, mesh_data, program_of};
use phong_core::Scene;
use serde_json::json;

/// One HTML file that draws `scene` with its exact shaders in WebGL2 (one sample a pixel).
/// The canvas is `#phong`; `window.phongDone` is set once it is drawn (or `window.phongError`
/// with the reason).
pub fn html(scene: &Scene) -> Result<String, Unsupported> {
    if scene.objects.is_empty() {
        return Err(Unsupported("the scene has no objects".into()));
    }
    // One program per distinct shading, in the objects' order; each object's index in it.
    let mut shadings: Vec<(phong_core::ShadingSettings, crate::Sampled)> = Vec::new();
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let key = (o.shading, crate::Sampled::of(o));
        let k = match shadings.iter().position(|s| *s == key) {
            Some(k) => k,
            None => {
                shadings.push(key);
                shadings.len() - 1
            }
        };
        let p = program_of(scene, i, Version::Es300)?;
        materials.push(p.uniforms["objects"][0]["uniforms"].clone());
        let mut mesh = mesh_data(o, k);
        let page = |m: &Option<phong_core::TextureMap>| m.as_ref().map(crate::texture::page_data).transpose();
        mesh["textures"] = json!({"diffuse": page(&o.maps.diffuse)?, "specular": page(&o.maps.specular)?});
        meshes.push(mesh);
    }
    let programs: Vec<_> = shadings
        .iter()
        .map(|s| {
            let first = scene
                .objects
                .iter()
                .position(|o| (o.shading, crate::Sampled::of(o)) == *s)
                .expect("an object has it");
            let p = program_of(scene, first, Version::Es300).expect("checked above");
            json!({"vertex": p.vertex, "fragment": p.fragment})
        })
        .collect();
    let bg = scene.image.background;
    let encode = |c: f32| f64::from(scene.image.encoding.encode(c)) / 255.0;
    let data = json!({
        "width": scene.image.width,
        "height": scene.image.height,
        "background": [encode(bg[0]), encode(bg[1]), encode(bg[2]), 1.0],
        "programs": programs,
        "scene": crate::scene_uniforms(scene),
        "materials": materials,
        "meshes": meshes,
        "labels": label_runs(scene),
    });
    // WebGL2 draws one sample a pixel; phong's antialiasing samples its own pattern.
    let samples = match scene.image.samples.count() {
        1 => String::new(),
        n => format!(
            "<p>One sample a pixel: compare with <code>phong render SCENE --antialias 1</code> \
             (the scene asks for {n}, in phong's own sample pattern, which WebGL2 cannot reproduce).</p>\n"
        ),
    };
    // `</` cannot close the script from inside a JSON string.
    let data = data.to_string().replace("</", "<\\/");
    // The page: its script reads the scene's data (`@DATA@`).
    Ok(include_str!("page.html")
        .replace("@SAMPLES@", &samples)
        .replace("@DATA@", &data))
}

/// The scene's labels as phong draws them over its image: runs `[x, y, length, r, g, b]` of
/// pixels of one colour (8-bit, in the image's encoding), rows from the top.
fn label_runs(scene: &Scene) -> Vec<[u32; 6]> {
    let (w, h) = (scene.image.width, scene.image.height);
    if scene.labels.is_empty() {
        return Vec::new();
    }
    let Ok(mut img) = phong_core::Image::new(w, h, [0.0; 4]) else {
        return Vec::new();
    };
    phong_core::text::draw_labels(&mut img, &scene.camera, &scene.labels);
    let enc = |c: f32| u32::from(scene.image.encoding.encode(c));
    let mut runs: Vec<[u32; 6]> = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let p = img.get(x, y);
            if p[3] == 0.0 {
                continue;
            }
            let c = [enc(p[0]), enc(p[1]), enc(p[2])];
            match runs.last_mut() {
                Some(r) if r[1] == y && r[0] + r[2] == x && r[3..] == c => r[2] += 1,
                _ => runs.push([x, y, 1, c[0], c[1], c[2]]),
            }
        }
    }
    runs
}
