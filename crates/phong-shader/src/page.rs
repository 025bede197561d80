//! The standalone WebGL2 page: the scene's meshes embedded, drawn with the exported GLSL ES
//! 3.00 shaders and the scene's camera at the scene's image size. No network, no library.

use crate::{Unsupported, Version, mesh_data, program};
use phong_core::Scene;
use serde_json::json;

/// One HTML file that draws `scene` with its exact shaders in WebGL2 (one sample a pixel).
/// The canvas is `#phong`; `window.phongDone` is set once it is drawn (or `window.phongError`
/// with the reason).
pub fn html(scene: &Scene) -> Result<String, Unsupported> {
    let p = program(scene, Version::Es300)?;
    let bg = scene.image.background;
    let encode = |c: f32| f64::from(scene.image.encoding.encode(c)) / 255.0;
    let data = json!({
        "width": scene.image.width,
        "height": scene.image.height,
        "background": [encode(bg[0]), encode(bg[1]), encode(bg[2]), 1.0],
        "vertex": p.vertex,
        "fragment": p.fragment,
        "uniforms": p.uniforms,
        "meshes": scene.objects.iter().map(mesh_data).collect::<Vec<_>>(),
    });
    // `</` cannot close the script from inside a JSON string.
    let data = data.to_string().replace("</", "<\\/");
    let labels = if scene.labels.is_empty() {
        ""
    } else {
        "<p>The scene's labels are not drawn here.</p>"
    };
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
{labels}
<details><summary>Vertex shader</summary><pre id="vs"></pre></details>
<details><summary>Fragment shader</summary><pre id="fs"></pre></details>
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
  document.getElementById("vs").textContent = scene.vertex;
  document.getElementById("fs").textContent = scene.fragment;
  const gl = canvas.getContext("webgl2", {{ antialias: false, preserveDrawingBuffer: true }});
  if (!gl) throw new Error("this browser has no WebGL2");
  const compile = (type, src) => {{
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }};
  const prog = gl.createProgram();
  gl.attachShader(prog, compile(gl.VERTEX_SHADER, scene.vertex));
  gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, scene.fragment));
  gl.bindAttribLocation(prog, 0, "position");
  gl.bindAttribLocation(prog, 1, "normal");
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  gl.useProgram(prog);
  const floats = ["uShininess", "uKd", "uKs", "uSpotCosCutoff", "uSpotExponent"];
  const set = (name, v) => {{
    const at = gl.getUniformLocation(prog, name);
    if (at === null) return;
    const arr = Array.isArray(v) ? v.flat() : [v];
    if (name === "uClipFromWorld") gl.uniformMatrix4fv(at, false, arr);
    else if (floats.includes(name)) gl.uniform1fv(at, arr);
    else gl.uniform3fv(at, arr);
  }};
  for (const [k, v] of Object.entries(scene.uniforms.scene)) if (!(Array.isArray(v) && v.length === 0)) set(k, v);
  gl.viewport(0, 0, scene.width, scene.height);
  gl.clearColor(...scene.background);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  gl.depthFunc(gl.LESS);
  scene.meshes.forEach((m, i) => {{
    for (const [k, v] of Object.entries(scene.uniforms.objects[i].uniforms)) set(k, v);
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    [m.positions, m.normals].forEach((b, loc) => {{
      const buf = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, buf);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(bytes(b)), gl.STATIC_DRAW);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
    }});
    const ib = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(bytes(m.indices)), gl.STATIC_DRAW);
    if (m.cull) gl.enable(gl.CULL_FACE); else gl.disable(gl.CULL_FACE);
    gl.drawElements(gl.TRIANGLES, m.count, gl.UNSIGNED_INT, 0);
  }});
  gl.finish();
}}
try {{ run(); window.phongDone = true; }} catch (e) {{ window.phongError = String(e); document.body.append(String(e)); }}
</script>
</body>
</html>
"#
    ))
}
