//! The three.js target: an ES module whose `phongMaterial(THREE, i)` returns a
//! `THREE.RawShaderMaterial` computing object `i`'s shading exactly (its lights and material as
//! uniforms; positions and normals through the mesh's `modelMatrix`, the eye from three's
//! camera), and an example page that draws the scene with it, importing three from a copy
//! beside it (`three.module.js`).

use crate::{Unsupported, Version, mesh_data, program_of, scene_uniforms};
use phong_core::{Interpolation, Scene};
use serde_json::{Value, json};

/// The ES 3.00 pair in three.js's terms: three supplies `#version`, the matrices and
/// `cameraPosition`; the mesh's own `modelMatrix` moves positions and normals to the world.
fn for_three(vertex: &str, fragment: &str, flat: bool) -> (String, String) {
    let lighting = |src: &str| {
        src.replace("#version 300 es\n", "")
            .replace(
                "uniform vec3 uEye, uToViewer, uGlobalAmbient;",
                "uniform vec3 cameraPosition, uGlobalAmbient;\nuniform mat4 viewMatrix;",
            )
            .replace("vec3 V = uEye - P;", "vec3 V = cameraPosition - P;")
            // The infinite viewer: the camera's +z axis (towards the viewer), in the world.
            .replace(
                "vec3 V = uToViewer;",
                "vec3 V = vec3(viewMatrix[0][2], viewMatrix[1][2], viewMatrix[2][2]);",
            )
    };
    let mut v = lighting(vertex);
    let matrices = if v.contains("uniform mat4 viewMatrix;") {
        "uniform mat4 modelMatrix, projectionMatrix;"
    } else {
        "uniform mat4 modelMatrix, viewMatrix, projectionMatrix;"
    };
    v = v.replace("uniform mat4 uClipFromWorld;", matrices).replace(
        "void main() {\n",
        &format!(
            "void main() {{\n    vec3 worldPosition = (modelMatrix * vec4(position, 1.0)).xyz;\n    \
             vec3 worldNormal = transpose(inverse(mat3(modelMatrix))) * normal;\n{}",
            if flat {
                "    vec3 worldCentroid = (modelMatrix * vec4(triangleCentroid, 1.0)).xyz;\n"
            } else {
                ""
            }
        ),
    );
    v = v
        .replace(
            "gl_Position = uClipFromWorld * vec4(position, 1.0);",
            "gl_Position = projectionMatrix * viewMatrix * vec4(worldPosition, 1.0);",
        )
        .replace("vPosition = position;", "vPosition = worldPosition;")
        .replace("vNormal = normal;", "vNormal = worldNormal;")
        .replace("shadePoint(position, normal)", "shadePoint(worldPosition, worldNormal)")
        .replace(
            "shadePoint(position, -normal)",
            "shadePoint(worldPosition, -worldNormal)",
        )
        .replace(
            "shadePoint(triangleCentroid, normal)",
            "shadePoint(worldCentroid, worldNormal)",
        )
        .replace(
            "shadePoint(triangleCentroid, -normal)",
            "shadePoint(worldCentroid, -worldNormal)",
        );
    (v, lighting(fragment))
}

/// The module (`phong-material.js`) and the example page (`index.html`) for `scene`.
pub fn threejs(scene: &Scene) -> Result<(String, String), Unsupported> {
    if scene.objects.is_empty() {
        return Err(Unsupported("the scene has no objects".into()));
    }
    let mut shadings = Vec::new();
    let mut programs = Vec::new();
    let mut objects = Vec::new();
    let mut meshes = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        if crate::Sampled::of(o) != crate::Sampled::default() {
            return Err(Unsupported(format!(
                "object `{}` has texture maps: the threejs target draws untextured materials (the glsl and html targets draw diffuse and specular maps)",
                o.name
            )));
        }
        let p = program_of(scene, i, Version::Es300)?;
        let k = match shadings.iter().position(|s| *s == o.shading) {
            Some(k) => k,
            None => {
                shadings.push(o.shading);
                let (vertex, fragment) =
                    for_three(&p.vertex, &p.fragment, o.shading.interpolation == Interpolation::Flat);
                programs.push(json!({"vertex": vertex, "fragment": fragment}));
                shadings.len() - 1
            }
        };
        objects.push(json!({
            "name": o.name,
            "program": k,
            "uniforms": p.uniforms["objects"][0]["uniforms"],
            "twoSided": o.shading.options.two_sided,
        }));
        meshes.push(mesh_data(o, k));
    }
    let mut lights = scene_uniforms(scene);
    for k in ["uClipFromWorld", "uEye", "uToViewer"] {
        lights.as_object_mut().expect("an object").remove(k);
    }
    let aspect = scene.image.width as f32 / scene.image.height as f32;
    let module = module_text(&programs, &lights, &objects);
    let bg = scene.image.background;
    let encode = |c: f32| f64::from(scene.image.encoding.encode(c)) / 255.0;
    let example = json!({
        "width": scene.image.width,
        "height": scene.image.height,
        "background": [encode(bg[0]), encode(bg[1]), encode(bg[2])],
        "worldFromView": scene.camera.view_from_world().inverse().to_cols_array(),
        "clipFromView": scene.camera.clip_from_view(aspect).to_cols_array(),
        "meshes": meshes,
    });
    Ok((module, example_page(&example)))
}

fn module_text(programs: &[Value], lights: &Value, objects: &[Value]) -> String {
    format!(
        r#"// Generated by `phong shader --target threejs`: the Phong illumination model of this scene as
// three.js materials, exactly as phong computes it (each program's comment states the
// equation). `phongMaterial(THREE, i)` is object i's material; its uniforms hold the scene's
// lights and the object's material, and can be changed (`material.uniforms.uDiffuse.value`).
// Meshes need `position` and `normal` attributes (and, for flat objects, `triangleCentroid`:
// every vertex its triangle's centroid, the mesh unshared, `normal` the facet normal).

export const programs = {programs};
export const lights = {lights};
export const objects = {objects};

// Uniforms holding floats (the others hold vec3s, or arrays of them).
const FLOATS = ["uShininess", "uKd", "uKs", "uSpotCosCutoff", "uSpotExponent"];

export function phongMaterial(THREE, i = 0) {{
  const object = objects[i];
  const program = programs[object.program];
  const uniforms = {{}};
  for (const [name, value] of Object.entries({{ ...lights, ...object.uniforms }})) {{
    let v = value;
    if (!FLOATS.includes(name)) {{
      v = Array.isArray(value[0]) ? value.map((c) => new THREE.Vector3(...c)) : new THREE.Vector3(...value);
    }}
    uniforms[name] = {{ value: v }};
  }}
  return new THREE.RawShaderMaterial({{
    glslVersion: THREE.GLSL3,
    vertexShader: program.vertex,
    fragmentShader: program.fragment,
    uniforms,
    side: object.twoSided ? THREE.DoubleSide : THREE.FrontSide,
  }});
}}
"#,
        programs = serde_json::to_string_pretty(programs).expect("JSON"),
        lights = serde_json::to_string_pretty(lights).expect("JSON"),
        objects = serde_json::to_string_pretty(objects).expect("JSON"),
    )
}

fn example_page(example: &Value) -> String {
    let data = example.to_string().replace("</", "<\\/");
    format!(
        r#"<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>phong: the scene in three.js with phong's materials</title>
<style>body {{ background: #222; color: #ddd; font: 14px system-ui, sans-serif; margin: 1em; }} canvas {{ display: block; }}</style>
</head>
<body>
<canvas id="phong"></canvas>
<p>three.js is imported from <code>three.module.js</code> beside this page (copy three's
<code>build/</code> files here), and modules load over HTTP: <code>python3 -m http.server</code>
in this folder, then open <code>http://localhost:8000/</code>.</p>
<script type="module">
import * as THREE from "./three.module.js";
import {{ phongMaterial }} from "./phong-material.js";
const data = {data};
function floats(b64) {{
  const s = atob(b64), bytes = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) bytes[i] = s.charCodeAt(i);
  return bytes.buffer;
}}
try {{
  const canvas = document.getElementById("phong");
  const renderer = new THREE.WebGLRenderer({{ canvas, antialias: false, preserveDrawingBuffer: true }});
  // The shaders write the image's own values: no colour conversion on the way out.
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  renderer.setPixelRatio(1);
  renderer.setSize(data.width, data.height, false);
  canvas.style.width = data.width / devicePixelRatio + "px";
  renderer.setClearColor(new THREE.Color(...data.background), 1);
  const scene = new THREE.Scene();
  data.meshes.forEach((m, i) => {{
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(new Float32Array(floats(m.positions)), 3));
    g.setAttribute("normal", new THREE.BufferAttribute(new Float32Array(floats(m.normals)), 3));
    if (m.centroids.length) g.setAttribute("triangleCentroid", new THREE.BufferAttribute(new Float32Array(floats(m.centroids)), 3));
    g.setIndex(new THREE.BufferAttribute(new Uint32Array(floats(m.indices)), 1));
    scene.add(new THREE.Mesh(g, phongMaterial(THREE, i)));
  }});
  // phong's camera, as its matrices.
  const camera = new THREE.Camera();
  camera.matrixAutoUpdate = false;
  camera.matrix.fromArray(data.worldFromView);
  camera.projectionMatrix.fromArray(data.clipFromView);
  camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
  camera.updateMatrixWorld(true);
  renderer.render(scene, camera);
  window.phongDone = true;
}} catch (e) {{
  window.phongError = String(e);
  document.body.append(String(e));
}}
</script>
</body>
</html>
"#
    )
}
