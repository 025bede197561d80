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
    Ok(format!(
        r#"<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>phong: the scene's shaders in WebGL2</title>
<style>
body {{ background: #222; color: #ddd; font: 14px system-ui, sans-serif; margin: 1em; }}
canvas {{ display: block; image-rendering: pixelated; }}
pre {{ background: #111; padding: 1em; overflow: auto; max-height: 30em; }}
</style>
</head>
<body>
<canvas id="phong"></canvas>
{samples}<div id="shaders"></div>
<script>
const scene = {data};
function bytes(b64) {{
  const s = atob(b64), out = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
  return out.buffer;
}}
function run() {{
  const canvas = document.getElementById("phong");
  canvas.width = scene.width;
  canvas.height = scene.height;
  // One CSS pixel an image pixel, whatever the screen's density.
  canvas.style.width = scene.width / devicePixelRatio + "px";
  canvas.style.height = scene.height / devicePixelRatio + "px";
  const gl = canvas.getContext("webgl2", {{ antialias: false, preserveDrawingBuffer: true }});
  if (!gl) throw new Error("this browser has no WebGL2");
  const compile = (type, src) => {{
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }};
  const programs = scene.programs.map((p, i) => {{
    for (const [what, src] of [["Vertex", p.vertex], ["Fragment", p.fragment]]) {{
      const d = document.createElement("details");
      d.innerHTML = "<summary></summary><pre></pre>";
      d.firstChild.textContent = what + " shader" + (scene.programs.length > 1 ? " " + (i + 1) : "");
      d.lastChild.textContent = src;
      document.getElementById("shaders").append(d);
    }}
    const prog = gl.createProgram();
    gl.attachShader(prog, compile(gl.VERTEX_SHADER, p.vertex));
    gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, p.fragment));
    gl.bindAttribLocation(prog, 0, "position");
    gl.bindAttribLocation(prog, 1, "normal");
    gl.bindAttribLocation(prog, 2, "triangleCentroid");
    gl.bindAttribLocation(prog, 3, "uv");
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    return prog;
  }});
  const floats = ["uShininess", "uKd", "uKs", "uSpotCosCutoff", "uSpotExponent"];
  const set = (prog, name, v) => {{
    const at = gl.getUniformLocation(prog, name);
    if (at === null) return;
    const arr = Array.isArray(v) ? v.flat() : [v];
    if (arr.length === 0) return;
    if (name === "uClipFromWorld") gl.uniformMatrix4fv(at, false, arr);
    else if (name.endsWith("Uv")) gl.uniformMatrix3fv(at, false, arr);
    else if (floats.includes(name)) gl.uniform1fv(at, arr);
    else gl.uniform3fv(at, arr);
  }};
  gl.viewport(0, 0, scene.width, scene.height);
  gl.clearColor(...scene.background);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  gl.depthFunc(gl.LESS);
  scene.meshes.forEach((m, i) => {{
    const prog = programs[m.program];
    gl.useProgram(prog);
    for (const [k, v] of Object.entries(scene.scene)) set(prog, k, v);
    for (const [k, v] of Object.entries(scene.materials[i])) set(prog, k, v);
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    [m.positions, m.normals, m.centroids, m.uvs].forEach((b, loc) => {{
      if (b.length === 0) return;
      const buf = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, buf);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(bytes(b)), gl.STATIC_DRAW);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, loc === 3 ? 2 : 3, gl.FLOAT, false, 0, 0);
    }});
    // The maps: phong's own mipmap levels, with the map's wrap and filters.
    [["uDiffuseMap", m.textures.diffuse], ["uSpecularMap", m.textures.specular]].forEach(([name, t], unit) => {{
      if (!t) return;
      gl.activeTexture(gl.TEXTURE0 + unit);
      gl.bindTexture(gl.TEXTURE_2D, gl.createTexture());
      gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
      t.levels.forEach((l, level) => {{
        if (t.half) gl.texImage2D(gl.TEXTURE_2D, level, gl.RGBA16F, l.width, l.height, 0, gl.RGBA, gl.HALF_FLOAT, new Uint16Array(bytes(l.data)));
        else gl.texImage2D(gl.TEXTURE_2D, level, gl.RGBA8, l.width, l.height, 0, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(bytes(l.data)));
      }});
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, t.levels.length - 1);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, t.wrapS);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, t.wrapT);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, t.mag);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, t.min);
      gl.uniform1i(gl.getUniformLocation(prog, name), unit);
    }});
    const ib = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(bytes(m.indices)), gl.STATIC_DRAW);
    if (m.cull) gl.enable(gl.CULL_FACE); else gl.disable(gl.CULL_FACE);
    gl.drawElements(gl.TRIANGLES, m.count, gl.UNSIGNED_INT, 0);
  }});
  // The labels: runs of pixels of one colour, each cleared in place (the image's rows from
  // the top, GL's from the bottom).
  gl.enable(gl.SCISSOR_TEST);
  for (const [x, y, n, r, g, b] of scene.labels) {{
    gl.scissor(x, scene.height - 1 - y, n, 1);
    gl.clearColor(r / 255, g / 255, b / 255, 1);
    gl.clear(gl.COLOR_BUFFER_BIT);
  }}
  gl.disable(gl.SCISSOR_TEST);
  gl.finish();
}}
try {{ run(); window.phongDone = true; }} catch (e) {{ window.phongError = String(e); document.body.append(String(e)); }}
</script>
</body>
</html>
"#
    ))
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
