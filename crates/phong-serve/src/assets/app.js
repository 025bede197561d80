// phong serve's page: controls edit a scene (the TOML file's schema, as JSON); the server
// renders it with phong's renderer and answers PNG files. The newest input always wins: at
// most one frame is in flight, and a newer input replaces the one waiting, never queues.
'use strict';

const $ = (id) => document.getElementById(id);
const CLIENT = (crypto.randomUUID ? crypto.randomUUID() : String(Math.random()).slice(2)).replace(/[^a-zA-Z0-9-]/g, '');
const HEADERS = { 'Content-Type': 'application/json', 'X-Phong-Client': CLIENT };
const SHAPES = ['sphere', 'torus', 'cylinder', 'cone', 'cube', 'plane', 'teapot'];
const OPENGL_DEFAULT = { ambient: [0.2, 0.2, 0.2], diffuse: [0.8, 0.8, 0.8], specular: [0, 0, 0], emission: [0, 0, 0], shininess: 0 };

const S = {
  scene: null,          // the scene JSON being edited
  original: null,       // the scene as opened (for the "scene" material)
  sel: 0,               // the object the Object controls edit
  view: 'render',
  compare: 'blinn4s',
  split: 50,
  difference: false,
  size: null,           // [w, h] fixed by ?size=WxH, else the viewport's
  materials: [],        // the 29 named materials, from /api/materials
  models: [],           // model names the server knows (command line) or this page uploaded
};

// Test and benchmark hooks: frame latencies, the last frame's PNG, whether work is pending.
const hooks = { frames: [], lastPng: null, keepPng: false, active: 0, timer: false, state: S };
hooks.idle = () => hooks.ready === true && hooks.active === 0 && !hooks.timer;
window.phong = hooks;

// ---------- small helpers ----------
const clone = (v) => JSON.parse(JSON.stringify(v));
const norm = (n) => String(n).toLowerCase().replace(/[\s_-]/g, '');
const hex = (c) => '#' + c.map((x) => Math.round(Math.min(1, Math.max(0, x)) * 255).toString(16).padStart(2, '0')).join('');
const unhex = (h) => [1, 3, 5].map((i) => parseInt(h.slice(i, i + 2), 16) / 255);
const fmt = (x, d = 4) => (typeof x === 'number' ? (Number.isInteger(x) ? String(x) : x.toFixed(d)) : String(x));
const vfmt = (v, d = 3) => '(' + v.map((x) => fmt(x, d)).join(', ') + ')';
const sub = (a, b) => a.map((x, i) => x - b[i]);
const add = (a, b) => a.map((x, i) => x + b[i]);
const scale = (a, k) => a.map((x) => x * k);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const len = (a) => Math.sqrt(dot(a, a));
const unit = (a) => { const l = len(a); return l > 0 ? scale(a, 1 / l) : a; };
function rotate(v, axis, ang) { // Rodrigues
  const k = unit(axis), c = Math.cos(ang), s = Math.sin(ang);
  return add(add(scale(v, c), scale(cross(k, v), s)), scale(k, dot(k, v) * (1 - c)));
}
function parseVec(text, n) {
  const parts = text.split(/[\s,]+/).filter((p) => p !== '');
  const v = parts.map(Number);
  if (v.length !== n || v.some((x) => !Number.isFinite(x))) return null;
  return v;
}

// ---------- the scene's parts ----------
const obj = () => S.scene.object[S.sel];
const cam = () => {
  const c = S.scene.camera || (S.scene.camera = {});
  c.position = c.position || [0, 0, 5];
  c.target = c.target || [0, 0, 0];
  return c;
};
const shading = () => S.scene.shading || (S.scene.shading = {});
const image = () => S.scene.image || (S.scene.image = {});

function namedMaterial(name) {
  const m = S.materials.find((m) => norm(m.name) === norm(name));
  return m ? { ambient: m.ambient, diffuse: m.diffuse, specular: m.specular, emission: m.emission, shininess: m.shininess } : null;
}

// The material's numbers as the scene reader computes them (for the colour inputs).
function effective(m, depth = 0) {
  if (m === undefined || depth > 8) return clone(OPENGL_DEFAULT);
  if (typeof m === 'string') {
    const mats = S.scene.materials || {};
    const own = Object.keys(mats).find((k) => norm(k) === norm(m));
    if (own !== undefined) return effective(mats[own], depth + 1);
    return namedMaterial(m) || clone(OPENGL_DEFAULT);
  }
  let start = m.base !== undefined ? effective(m.base, depth + 1)
    : m.paint ? { ambient: [0, 0, 0], diffuse: [0, 0, 0], specular: [1, 1, 1], emission: [0, 0, 0], shininess: 0 }
      : clone(OPENGL_DEFAULT);
  return {
    ambient: m.ambient || m.paint || start.ambient,
    diffuse: m.diffuse || m.paint || start.diffuse,
    specular: m.specular || start.specular,
    emission: m.emission || start.emission,
    shininess: m.shininess !== undefined ? m.shininess : start.shininess,
  };
}

// Shininess slider: 0 at the left end, then logarithmic from 1 to 1000.
const shininessFromSlider = (p) => (p <= 0 ? 0 : Math.round(Math.pow(1000, p / 1000) * 100) / 100);
const sliderFromShininess = (s) => (s <= 0 ? 0 : Math.max(1, Math.round((1000 * Math.log(Math.max(1, s))) / Math.log(1000))));

// ---------- image size ----------
// The size a picture is drawn at: the width `el` is shown at, in device pixels, at the
// viewport's 16:9 (or the URL's `size`, which pins every view's).
function shownSize(el) {
  if (S.size) return S.size;
  const w = Math.max(64, Math.min(3840, Math.round(el.clientWidth * (window.devicePixelRatio || 1))));
  return [w, Math.max(36, Math.round((w * 9) / 16))];
}

// The render view's frame: its viewport, or where that view is hidden, the stage it would fill.
function frameSize() {
  return shownSize($('viewport').clientWidth ? $('viewport') : $('stage'));
}

// Previews (while the user drags) have one sample, and half the size where the frame has
// more than half a megapixel (`?preview=full` keeps the size); the full frame follows.
function sceneFor(preview, overrides) {
  const s = clone(S.scene);
  s.image = s.image || {};
  let [w, h] = frameSize();
  if (preview && S.previewScale !== 1 && w * h > 500000) {
    w = Math.max(1, Math.round(w / 2));
    h = Math.max(1, Math.round(h / 2));
  }
  s.image.width = w;
  s.image.height = h;
  if (preview) s.image.antialias = 1;
  if (overrides) overrides(s);
  return s;
}

// ---------- errors ----------
function clearErrors() {
  document.querySelectorAll('.err').forEach((e) => { e.textContent = ''; });
  document.querySelectorAll('.invalid').forEach((e) => e.classList.remove('invalid'));
  $('error').textContent = '';
}

// The control a scene path belongs to.
function controlFor(path) {
  let m;
  if ((m = /^shading\.(\w+)/.exec(path))) return { two_sided: 'two-sided' }[m[1]] || m[1];
  if ((m = /^image\.(\w+)/.exec(path))) return m[1];
  if ((m = /^object\[(\d+)\]\.(\w+)/.exec(path)) && Number(m[1]) === S.sel) {
    const k = m[2];
    if (k === 'material') return path.includes('shininess') ? 'shininess' : 'material';
    if (k === 'segments' || k === 'shape' || k === 'mesh') return k === 'mesh' ? 'shape' : k;
  }
  if ((m = /^light\[(\d+)\](?:\.(\w+))?/.exec(path))) return `light-${Number(m[1]) + 1}-${m[2] || 'type'}`;
  return null;
}

function showError(err) {
  const message = err.path ? `${err.path}: ${err.error}` : err.error;
  const id = err.path ? controlFor(err.path) : null;
  const slot = id && document.querySelector(`.err[data-for="${id}"]`);
  if (slot) {
    slot.textContent = err.error;
    const c = $(id);
    if (c) c.classList.add('invalid');
  }
  $('error').textContent = message;
}

// ---------- rendering ----------
let pending = null;   // the newest frame asked for, not yet sent
let inflight = false;
let fullTimer = null;
let generation = 0;   // bumps on every input; other views drop older answers

async function post(url, body) {
  hooks.active++;
  try {
    const r = await fetch(url, { method: 'POST', headers: HEADERS, body: JSON.stringify(body) });
    if (!r.ok) {
      let e;
      try { e = await r.json(); } catch { e = { error: `HTTP ${r.status}` }; }
      throw e;
    }
    return r;
  } finally {
    hooks.active--;
  }
}

function changed(preview) {
  generation++;
  saveUrl();
  const t0 = performance.now();
  clearTimeout(fullTimer);
  hooks.timer = false;
  if (S.view === 'render') {
    if (preview) {
      requestFrame(true, t0);
      hooks.timer = true;
      fullTimer = setTimeout(() => { hooks.timer = false; requestFrame(false, performance.now()); }, 250);
    } else {
      requestFrame(false, t0);
    }
  } else if (S.view === 'terms') renderTerms();
  else if (S.view === 'compare') renderCompare();
  else if (S.view === 'lobe') renderLobe();
  else if (S.view === 'shader') renderShader();
}

function requestFrame(preview, t0) {
  pending = { scene: sceneFor(preview), preview, t0 };
  pump();
}

async function pump() {
  if (inflight || !pending) return;
  const job = pending;
  pending = null;
  inflight = true;
  hooks.active++;
  try {
    // Previews come as raw RGBA pixels (no PNG to encode or decode); full frames as the PNG
    // file `phong render` writes, which the page keeps for download.
    const tSend = performance.now();
    const r = await post(job.preview ? '/api/render?format=rgba' : '/api/render', job.scene);
    const tHeaders = performance.now();
    const blob = job.preview ? null : await r.blob();
    const buffer = job.preview ? await r.arrayBuffer() : null;
    const tBody = performance.now();
    const canvas = $('frame');
    const w = Number(r.headers.get('x-phong-width')), h = Number(r.headers.get('x-phong-height'));
    let picture;
    if (job.preview) {
      picture = new ImageData(new Uint8ClampedArray(buffer), w, h);
    } else {
      if (hooks.keepPng) hooks.lastPng = await blobBase64(blob);
      picture = await createImageBitmap(blob, { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
    }
    const tDecoded = performance.now();
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    const ctx = canvas.getContext('2d');
    if (job.preview) ctx.putImageData(picture, 0, 0);
    else { ctx.clearRect(0, 0, w, h); ctx.drawImage(picture, 0, 0); picture.close(); }
    requestAnimationFrame(() => {
      const painted = performance.now();
      hooks.frames.push({
        ms: painted - job.t0, preview: job.preview, render_ms: Number(r.headers.get('x-phong-render-ms')),
        wait: tSend - job.t0, response: tHeaders - tSend, body: tBody - tHeaders, decode: tDecoded - tBody, paint: painted - tDecoded,
        bytes: job.preview ? buffer.byteLength : blob.size, w, h,
      });
      if (hooks.frames.length > 5000) hooks.frames.shift();
    });
    S.shown = job.scene;
    clearErrors();
    $('status').textContent = `${job.scene.image.width}×${job.scene.image.height}, ${job.preview ? 'preview (1 sample)' : (job.scene.image.antialias || 1) + ' samples'}, rendered in ${r.headers.get('x-phong-render-ms')} ms`;
    drawMarkers();
  } catch (e) {
    showError(e.error ? e : { error: String(e) });
  } finally {
    inflight = false;
    hooks.active--;
    pump();
  }
}

function blobBase64(blob) {
  return new Promise((resolve) => {
    const fr = new FileReader();
    fr.onload = () => resolve(String(fr.result).split(',')[1]);
    fr.readAsDataURL(blob);
  });
}

async function renderTerms() {
  const g = generation;
  // Each term at the width its figure is shown at.
  const half = shownSize($('term-total').parentElement);
  const terms = { ambient: 'term-ambient', diffuse: 'term-diffuse', specular: 'term-specular', color: 'term-total' };
  hooks.active++;
  try {
    await Promise.all(Object.entries(terms).map(async ([term, id]) => {
      const s = sceneFor(false, (s) => {
        s.image.width = half[0]; s.image.height = half[1];
        s.image.background = [0, 0, 0];
        s.shading = s.shading || {};
        s.shading.output = term;
        s.object.forEach((o) => delete o.output);
      });
      const r = await post('/api/render', s);
      const blob = await r.blob();
      if (g !== generation) return;
      const img = $(id);
      img.src = URL.createObjectURL(blob);
      await img.decode();
    }));
    if (g === generation) clearErrors();
  } catch (e) {
    showError(e.error ? e : { error: String(e) });
  } finally {
    hooks.active--;
  }
}

// The compared setting: what changes against the current scene.
function variant(kind) {
  const m = effective(obj().material);
  const s = m.shininess;
  const setAll = (k, v) => (sc) => { sc.shading = sc.shading || {}; sc.shading[k] = v; sc.object.forEach((o) => delete o[k]); };
  const withShininess = (k) => (sc) => {
    sc.object.forEach((o) => { const e = effective(o.material); e.shininess = e.shininess * k; o.material = e; });
  };
  return {
    blinn4s: ['Blinn-Phong at 4s', (sc) => { setAll('model', 'blinn-phong')(sc); withShininess(4)(sc); }],
    blinn: ['Blinn-Phong at s', setAll('model', 'blinn-phong')],
    phong: ['Phong at s', setAll('model', 'phong')],
    lyon: ['Phong-Lyon at s', setAll('model', 'phong-lyon')],
    gouraud: ['Gouraud', setAll('interpolation', 'gouraud')],
    flat: ['flat', setAll('interpolation', 'flat')],
    'phong-interp': ['Phong interpolation', setAll('interpolation', 'phong')],
    normalized: ['normalized (' + (shading().model === 'phong' ? 'phong' : 'blinn-phong') + ')', (sc) => { sc.shading = sc.shading || {}; sc.shading.normalization = sc.shading.model === 'phong' ? 'phong' : 'blinn-phong'; }],
    'not-normalized': ['not normalized', (sc) => { sc.shading = sc.shading || {}; sc.shading.normalization = 'none'; }],
  }[kind] || ['same', () => {}];
}

let compareImages = null;
async function renderCompare() {
  const g = generation;
  const [name, change] = variant(S.compare);
  // At the width the comparison is shown at.
  const [w, h] = shownSize($('compare-canvas'));
  const sized = (s) => { s.image.width = w; s.image.height = h; };
  const a = sceneFor(false, sized);
  const b = sceneFor(false, (s) => { change(s); sized(s); });
  hooks.active++;
  try {
    const [ra, rb] = await Promise.all([post('/api/render', a), post('/api/render', b)]);
    const [ia, ib] = await Promise.all([createImageBitmap(await ra.blob()), createImageBitmap(await rb.blob())]);
    if (g !== generation) return;
    compareImages = [ia, ib];
    $('compare-legend').textContent = `left: current (${a.shading && a.shading.model || 'blinn-phong'}, ${a.shading && a.shading.interpolation || 'phong'}) · right: ${name}`;
    drawCompare();
    clearErrors();
  } catch (e) {
    showError(e.error ? e : { error: String(e) });
  } finally {
    hooks.active--;
  }
}

function drawCompare() {
  if (!compareImages) return;
  const [a, b] = compareImages;
  const c = $('compare-canvas');
  c.width = a.width; c.height = a.height;
  const ctx = c.getContext('2d');
  if (S.difference) {
    ctx.drawImage(a, 0, 0);
    const da = ctx.getImageData(0, 0, a.width, a.height);
    ctx.drawImage(b, 0, 0);
    const db = ctx.getImageData(0, 0, a.width, a.height);
    let max = 0;
    for (let i = 0; i < da.data.length; i += 4) {
      for (let k = 0; k < 3; k++) {
        const d = Math.abs(da.data[i + k] - db.data[i + k]);
        max = Math.max(max, d);
        da.data[i + k] = Math.min(255, d * 4);
      }
    }
    ctx.putImageData(da, 0, 0);
    $('compare-legend').textContent += ` · |left − right| × 4, largest difference ${max}/255`;
  } else {
    const x = Math.round((a.width * S.split) / 100);
    ctx.drawImage(a, 0, 0);
    if (x < a.width) ctx.drawImage(b, x, 0, a.width - x, a.height, x, 0, a.width - x, a.height);
    ctx.fillStyle = '#f0b429';
    ctx.fillRect(Math.min(x, a.width - 1), 0, 1, a.height);
  }
}

async function renderLobe() {
  const g = generation;
  const s = effective(obj().material).shininess;
  const sq = shading().lyon_squarings !== undefined ? shading().lyon_squarings : 3;
  hooks.active++;
  try {
    const r = await fetch(`/api/lobe?shininess=${s}&squarings=${sq}`);
    const d = await r.json();
    if (!r.ok) throw d;
    if (g !== generation) return;
    const c = $('lobe-canvas');
    const ctx = c.getContext('2d');
    const W = c.width, H = c.height, m = 40;
    ctx.fillStyle = '#000'; ctx.fillRect(0, 0, W, H);
    ctx.strokeStyle = '#444'; ctx.fillStyle = '#aaa'; ctx.font = '12px sans-serif';
    const X = (a) => m + ((a + 90) / 180) * (W - 2 * m);
    const Y = (v) => H - m - v * (H - 2 * m);
    for (let a = -90; a <= 90; a += 30) { ctx.beginPath(); ctx.moveTo(X(a), Y(0)); ctx.lineTo(X(a), Y(1)); ctx.stroke(); ctx.fillText(`${a}°`, X(a) - 10, H - m + 16); }
    for (let v = 0; v <= 1; v += 0.25) { ctx.beginPath(); ctx.moveTo(X(-90), Y(v)); ctx.lineTo(X(90), Y(v)); ctx.stroke(); ctx.fillText(v.toFixed(2), 4, Y(v) + 4); }
    const curves = [['phong', '#f0b429', 'Phong (R·V)^s'], ['blinn_phong', '#4fc3f7', 'Blinn-Phong (N·H)^s'], ['blinn_phong_4s', '#81c784', 'Blinn-Phong (N·H)^4s'], ['lyon', '#e57373', `Lyon, γ = ${2 ** sq}`]];
    for (const [k, color] of curves) {
      ctx.strokeStyle = color; ctx.lineWidth = 2; ctx.beginPath();
      d.angles.forEach((a, i) => (i ? ctx.lineTo(X(a), Y(d[k][i])) : ctx.moveTo(X(a), Y(d[k][i]))));
      ctx.stroke();
    }
    ctx.lineWidth = 1;
    $('lobe-legend').innerHTML = `shininess s = ${fmt(s, 2)} · ` + curves.map(([, c, n]) => `<span style="color:${c}">■ ${n}</span>`).join(' · ');
    hooks.lobe = d;
  } catch (e) {
    showError(e.error ? e : { error: String(e) });
  } finally {
    hooks.active--;
  }
}

// ---------- camera and lights on screen ----------
function cameraBasis(c) {
  const f = unit(sub(c.target, c.position));
  const upv = c.up || [0, 1, 0];
  const r = unit(cross(f, upv));
  return { f, r, u: cross(r, f) };
}

// World point to displayed CSS pixels (null when behind the camera).
function project(p) {
  const c = cam();
  const { f, r, u } = cameraBasis(c);
  const d = sub(p, c.position);
  const z = dot(d, f);
  const vp = $('viewport');
  const W = vp.clientWidth, H = vp.clientHeight;
  if (c.projection === 'orthographic') {
    const h = (c.height || 3) / 2, w = h * (W / H);
    return { x: (dot(d, r) / w * 0.5 + 0.5) * W, y: (0.5 - dot(d, u) / h * 0.5) * H };
  }
  if (z <= 1e-6) return null;
  const t = Math.tan(((c.fov || 45) * Math.PI) / 360);
  const ndcx = dot(d, r) / (z * t * (W / H));
  const ndcy = dot(d, u) / (z * t);
  return { x: (ndcx * 0.5 + 0.5) * W, y: (0.5 - ndcy * 0.5) * H };
}

function worldPerPixel(depth) {
  const c = cam();
  const H = $('viewport').clientHeight || 1;
  if (c.projection === 'orthographic') return (c.height || 3) / H;
  return (2 * depth * Math.tan(((c.fov || 45) * Math.PI) / 360)) / H;
}

function markerPoint(l) {
  if (l.type === 'directional') {
    const c = cam();
    const dist = len(sub(c.position, c.target));
    return add(c.target, scale(unit(l.direction || [0, -1, 0]), -0.6 * dist));
  }
  return l.position || [0, 0, 0];
}

function drawMarkers() {
  const svg = $('markers');
  svg.innerHTML = '';
  (S.scene.light || []).forEach((l, i) => {
    const p = project(markerPoint(l));
    if (!p) return;
    const g = document.createElementNS('http://www.w3.org/2000/svg', 'g');
    g.setAttribute('class', 'marker');
    g.setAttribute('data-light', String(i));
    g.setAttribute('aria-label', `Light ${i + 1} marker`);
    const col = hex(l.color || l.diffuse || [1, 1, 1]);
    if (l.type === 'directional') {
      const t = project(cam().target);
      if (t) {
        const line = document.createElementNS('http://www.w3.org/2000/svg', 'line');
        Object.entries({ x1: p.x, y1: p.y, x2: p.x + (t.x - p.x) * 0.25, y2: p.y + (t.y - p.y) * 0.25, stroke: col, 'stroke-width': 2 }).forEach(([k, v]) => line.setAttribute(k, v));
        g.appendChild(line);
      }
    }
    const circle = document.createElementNS('http://www.w3.org/2000/svg', l.type === 'directional' ? 'rect' : 'circle');
    if (l.type === 'directional') {
      Object.entries({ x: p.x - 7, y: p.y - 7, width: 14, height: 14 }).forEach(([k, v]) => circle.setAttribute(k, v));
    } else {
      Object.entries({ cx: p.x, cy: p.y, r: 8 }).forEach(([k, v]) => circle.setAttribute(k, v));
    }
    circle.setAttribute('fill', col);
    circle.setAttribute('stroke', '#000');
    circle.setAttribute('stroke-width', '2');
    g.appendChild(circle);
    const text = document.createElementNS('http://www.w3.org/2000/svg', 'text');
    Object.entries({ x: p.x + 10, y: p.y - 10, fill: '#fff', 'font-size': 12 }).forEach(([k, v]) => text.setAttribute(k, v));
    text.textContent = String(i + 1);
    g.appendChild(text);
    g.addEventListener('pointerdown', (ev) => startLightDrag(ev, i));
    svg.appendChild(g);
  });
}

let drag = null;
function startLightDrag(ev, i) {
  ev.stopPropagation();
  ev.preventDefault();
  drag = { kind: 'light', i, x: ev.clientX, y: ev.clientY };
  window.addEventListener('pointermove', onDragMove);
  window.addEventListener('pointerup', onDragEnd, { once: true });
}

function onViewportDown(ev) {
  if (ev.button !== 0) return;
  drag = { kind: ev.shiftKey ? 'pan' : 'orbit', x: ev.clientX, y: ev.clientY, x0: ev.clientX, y0: ev.clientY, moved: false };
  window.addEventListener('pointermove', onDragMove);
  window.addEventListener('pointerup', onDragEnd, { once: true });
}

function onDragMove(ev) {
  if (!drag) return;
  const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
  drag.x = ev.clientX; drag.y = ev.clientY;
  if (Math.abs(ev.clientX - (drag.x0 ?? ev.clientX)) + Math.abs(ev.clientY - (drag.y0 ?? ev.clientY)) > 3) drag.moved = true;
  if (drag.kind !== 'light' && !drag.moved) return;
  const c = cam();
  const { f, r, u } = cameraBasis(c);
  if (drag.kind === 'orbit') {
    const up = c.up || [0, 1, 0];
    let off = sub(c.position, c.target);
    off = rotate(off, up, -dx * 0.01);
    const side = unit(cross(up, off));
    const turned = rotate(off, side, -dy * 0.01);
    // Stay away from the poles, where the view would flip.
    if (Math.abs(dot(unit(turned), unit(up))) < 0.995) off = turned;
    c.position = add(c.target, off);
  } else if (drag.kind === 'pan') {
    const k = worldPerPixel(len(sub(c.target, c.position)));
    const move = add(scale(r, -dx * k), scale(u, dy * k));
    c.position = add(c.position, move);
    c.target = add(c.target, move);
  } else if (drag.kind === 'light') {
    const l = S.scene.light[drag.i];
    if (l.type === 'directional') {
      let d = l.direction || [0, -1, 0];
      d = rotate(d, c.up || [0, 1, 0], dx * 0.01);
      d = rotate(d, r, dy * 0.01);
      l.direction = d.map((x) => Math.round(x * 1e4) / 1e4);
    } else {
      const p = l.position || [0, 0, 0];
      const k = worldPerPixel(Math.max(1e-3, dot(sub(p, c.position), f)));
      l.position = add(p, add(scale(r, dx * k), scale(u, -dy * k))).map((x) => Math.round(x * 1e4) / 1e4);
    }
    buildLights();
  }
  drawMarkers();
  changed(true);
}

function onDragEnd(ev) {
  window.removeEventListener('pointermove', onDragMove);
  const d = drag;
  drag = null;
  if (!d) return;
  if ((d.kind === 'orbit' || d.kind === 'pan') && !d.moved) {
    probeAt(ev);
    return;
  }
  changed(false);
}

function onWheel(ev) {
  ev.preventDefault();
  const c = cam();
  if (c.projection === 'orthographic') {
    c.height = (c.height || 3) * Math.exp(ev.deltaY * 0.001);
  } else {
    const off = sub(c.position, c.target);
    c.position = add(c.target, scale(off, Math.exp(ev.deltaY * 0.001)));
  }
  drawMarkers();
  changed(true);
}

// ---------- the probe ----------
async function probeAt(ev) {
  const img = $('frame');
  const rect = img.getBoundingClientRect();
  const shown = S.shown || sceneFor(false);
  const x = Math.floor(((ev.clientX - rect.left) / rect.width) * shown.image.width);
  const y = Math.floor(((ev.clientY - rect.top) / rect.height) * shown.image.height);
  if (x < 0 || y < 0 || x >= shown.image.width || y >= shown.image.height) return;
  await probe(x, y);
}

async function probe(x, y) {
  const scene = sceneFor(false);
  try {
    const r = await post('/api/probe', { scene, x, y });
    const p = await r.json();
    hooks.probe = p;
    showProbe(p);
  } catch (e) {
    showError(e.error ? e : { error: String(e) });
  }
}
hooks.probeAt = probe;
hooks.rerender = () => changed(false);

function showProbe(p) {
  const body = $('probe-body');
  const rgb = (c) => vfmt(c, 4);
  let html = `<p>pixel (${p.x}, ${p.y}): value ${rgb(p.value)} → bytes (${p.value8.join(', ')})</p>`;
  for (const n of p.notes) html += `<p class="caption">${n}</p>`;
  const h = p.hit;
  if (!h) {
    body.innerHTML = html + '<p>background: no surface here.</p>';
    return;
  }
  const m = h.material;
  html += `<p>object ${h.object} (${h.name}), triangle ${h.triangle}${h.back_face ? ', back face (normals flipped)' : ''}, barycentric ${vfmt(h.barycentric, 4)},
    ${h.interpolation} interpolation, output ${h.output}, model ${h.specular_model}</p>`;
  html += `<table><tr><th>P</th><td>${vfmt(h.position)}</td><th>N</th><td>${vfmt(h.normal)}</td><th>V</th><td>${vfmt(h.view)}</td></tr>
    <tr><th>a<sub>m</sub></th><td>${rgb(m.ambient)}</td><th>d<sub>m</sub></th><td>${rgb(m.diffuse)}</td><th>s<sub>m</sub></th><td>${rgb(m.specular)}</td></tr>
    <tr><th>e<sub>m</sub></th><td>${rgb(m.emission)}</td><th>s</th><td>${fmt(m.shininess, 2)}</td><th>k<sub>d</sub>, k<sub>s</sub></th><td>${fmt(h.normalization[0])}, ${fmt(h.normalization[1])}</td></tr></table>`;
  if (h.texture) {
    const t = h.texture;
    html += `<table><tr><th>uv</th><td>${vfmt(t.uv, 4)}</td><th>∂uv/∂x</th><td>${vfmt(t.uv_dx, 5)}</td><th>∂uv/∂y</th><td>${vfmt(t.uv_dy, 5)}</td></tr>
      <tr><th>T<sub>Kd</sub></th><td>${vfmt(t.diffuse, 4)}</td><th>T<sub>Ks</sub></th><td>${rgb(t.specular)}</td><th>T<sub>Ns</sub></th><td>${fmt(t.shininess, 2)}</td></tr>
      <tr><th>T<sub>AO</sub></th><td>${fmt(t.occlusion)}</td><th>alpha</th><td>${fmt(t.alpha)}${t.discarded ? ' (discarded by the alpha test)' : ''}</td><td colspan="2"></td></tr></table>`;
  }
  html += '<table><tr><th>light</th><th>L</th><th>R</th><th>H</th><th>N·L</th><th>R·V</th><th>N·H</th><th>att</th><th>spot</th><th>spec</th><th>ambient</th><th>diffuse</th><th>specular</th></tr>';
  h.lights.forEach((l, i) => {
    html += `<tr><td>${i + 1} ${l.kind}</td><td>${vfmt(l.l)}</td><td>${vfmt(l.r)}</td><td>${vfmt(l.h)}</td><td>${fmt(l.n_dot_l)}</td><td>${fmt(l.r_dot_v)}</td>
      <td>${fmt(l.n_dot_h)}</td><td>${fmt(l.attenuation)}</td><td>${fmt(l.spot)}</td><td>${fmt(l.spec)}${l.lit ? '' : ' (gated: N·L ≤ 0)'}</td><td>${rgb(l.ambient)}</td><td>${rgb(l.diffuse)}</td><td>${rgb(l.specular)}</td></tr>`;
  });
  html += `<tr><th>sum</th><td colspan="9"></td><td>${rgb(h.ambient)}</td><td>${rgb(h.diffuse)}</td><td>${rgb(h.specular)}</td></tr></table>`;
  // The equation with the numbers, per channel.
  const ch = ['R', 'G', 'B'];
  let eq = 'c = e_m + a_m·a_g + Σ att·spot·[a_m·a_l + k_d·(N·L)⁺·d_m·d_l + k_s·f·spec·s_m·s_l]\n';
  for (let k = 0; k < 3; k++) {
    let line = `${ch[k]}: ${fmt(m.emission[k])} + ${fmt(m.ambient[k])}·${fmt(h.ambient_light[k])}`;
    h.lights.forEach((l) => {
      const f = l.lit ? 1 : 0;
      line += ` + ${fmt(l.attenuation)}·${fmt(l.spot)}·[${fmt(m.ambient[k])}·${fmt(l.colors[0][k])} + ${fmt(h.normalization[0])}·${fmt(Math.max(0, l.n_dot_l))}·${fmt(m.diffuse[k])}·${fmt(l.colors[1][k])} + ${fmt(h.normalization[1])}·${f}·${fmt(l.spec)}${h.normalization[1] !== 1 ? '·' + fmt(Math.max(0, l.n_dot_l)) : ''}·${fmt(m.specular[k])}·${fmt(l.colors[2][k])}]`;
    });
    line += ` = ${fmt(h.sum[k])}${h.clamp && h.sum[k] > 1 ? ' → clamped to 1' : ''}`;
    eq += line + '\n';
  }
  eq += `ambient ${rgb(h.ambient)} + diffuse ${rgb(h.diffuse)} + specular ${rgb(h.specular)} = ${rgb(h.sum)}; colour ${rgb(h.color)}\n`;
  if (h.vertices.length) {
    eq += 'Gouraud: the pixel is Σ λ_i·c_i of the vertices\' values:\n';
    h.vertices.forEach((v, i) => { eq += `  vertex ${i}: P ${vfmt(v.position)} N ${vfmt(v.normal)} c ${rgb(v.value)} λ ${fmt(h.barycentric[i])}\n`; });
  }
  eq += `pixel value ${rgb(p.value)} → ${p.value8.join(', ')} / 255`;
  html += `<pre id="probe-equation">${eq}</pre>`;
  body.innerHTML = html;
}

// ---------- controls ----------
function setOptions(select, values, current) {
  select.innerHTML = '';
  for (const [v, text] of values) {
    const o = document.createElement('option');
    o.value = v; o.textContent = text;
    select.appendChild(o);
  }
  select.value = current;
}

function syncControls() {
  const sh = shading();
  $('model').value = sh.model || 'blinn-phong';
  $('interpolation').value = sh.interpolation || 'phong';
  $('normalization').value = sh.normalization || 'none';
  $('viewer').value = sh.viewer || (cam().projection === 'orthographic' ? 'infinite' : 'local');
  $('two-sided').checked = !!sh.two_sided;
  $('output').value = sh.output || 'color';
  $('antialias').value = String(image().antialias || 1);
  $('encoding').value = image().encoding || 'linear';
  setOptions($('object'), S.scene.object.map((o, i) => [String(i), `${i + 1}: ${o.shape || o.mesh}`]), String(S.sel));
  const o = obj();
  setOptions($('shape'), SHAPES.concat(S.models).map((s) => [s, s]), o.shape || o.mesh);
  const segs = o.segments !== undefined ? o.segments : { plane: 1, teapot: 10 }[o.shape] || 64;
  $('segments').value = segs;
  $('segments').min = o.shape === 'plane' || o.shape === 'teapot' ? 1 : 3;
  $('segments').disabled = !o.shape || o.shape === 'cube';
  $('segments-value').textContent = o.shape && o.shape !== 'cube' ? segs : '—';
  const mats = [];
  const orig = S.original.object[S.sel];
  if (orig) mats.push(['scene', orig.material === undefined ? "the model's own" : "the scene's own"]);
  for (const m of S.materials) mats.push([m.name, m.name]);
  mats.push(['custom', 'custom']);
  let current = 'custom';
  if (typeof o.material === 'string' && namedMaterial(o.material) && !(S.scene.materials || {})[o.material]) current = S.materials.find((m) => norm(m.name) === norm(o.material)).name;
  else if (orig && JSON.stringify(o.material) === JSON.stringify(orig.material)) current = 'scene';
  else if (!orig && o.material === undefined) current = 'custom';
  setOptions($('material'), mats, current);
  const e = effective(o.material);
  $('shininess').value = sliderFromShininess(e.shininess);
  $('shininess-value').textContent = fmt(e.shininess, 2);
  for (const k of ['ambient', 'diffuse', 'specular', 'emission']) $(k).value = hex(e[k]);
  buildLights();
}

function setShading(key, value, perObject) {
  shading()[key] = value;
  if (perObject) S.scene.object.forEach((o) => delete o[perObject]);
}

function customMaterial(change) {
  const o = obj();
  const e = effective(o.material);
  change(e);
  o.material = { ambient: e.ambient, diffuse: e.diffuse, specular: e.specular, emission: e.emission, shininess: e.shininess };
  $('material').value = 'custom';
}

function bindControls() {
  const on = (id, ev, f) => $(id).addEventListener(ev, f);
  on('model', 'change', (e) => { setShading('model', e.target.value, 'model'); changed(false); });
  on('interpolation', 'change', (e) => { setShading('interpolation', e.target.value, 'interpolation'); changed(false); });
  on('normalization', 'change', (e) => { setShading('normalization', e.target.value); changed(false); });
  on('viewer', 'change', (e) => { setShading('viewer', e.target.value); changed(false); });
  on('two-sided', 'change', (e) => { setShading('two_sided', e.target.checked); changed(false); });
  on('output', 'change', (e) => { setShading('output', e.target.value, 'output'); changed(false); });
  on('antialias', 'change', (e) => { image().antialias = Number(e.target.value); changed(false); });
  on('encoding', 'change', (e) => { image().encoding = e.target.value; changed(false); });
  on('object', 'change', (e) => { S.sel = Number(e.target.value); syncControls(); saveUrl(); });
  on('shape', 'change', (e) => {
    const o = obj();
    const v = e.target.value;
    if (SHAPES.includes(v)) {
      delete o.mesh; delete o.normals; o.shape = v;
      if (v === 'cube') delete o.segments;
      if (v !== 'torus') { delete o.radius; delete o.tube; }
    } else {
      delete o.shape; delete o.segments; delete o.radius; delete o.tube; delete o.normals; o.mesh = v;
    }
    syncControls();
    changed(false);
  });
  on('segments', 'input', (e) => { obj().segments = Number(e.target.value); $('segments-value').textContent = e.target.value; changed(true); });
  on('material', 'change', (e) => {
    const v = e.target.value;
    const o = obj();
    if (v === 'scene') {
      const m = S.original.object[S.sel] && S.original.object[S.sel].material;
      if (m === undefined) delete o.material; else o.material = clone(m);
    }
    else if (v === 'custom') customMaterial(() => {});
    else o.material = v;
    syncControls();
    changed(false);
  });
  on('shininess', 'input', (e) => {
    const s = shininessFromSlider(Number(e.target.value));
    customMaterial((m) => { m.shininess = s; });
    $('shininess-value').textContent = fmt(s, 2);
    changed(true);
  });
  for (const k of ['ambient', 'diffuse', 'specular', 'emission']) {
    on(k, 'input', (e) => { customMaterial((m) => { m[k] = unhex(e.target.value); }); changed(true); });
  }
  on('add-light', 'click', () => {
    S.scene.light = S.scene.light || [];
    const c = cam();
    S.scene.light.push({ type: 'point', position: add(c.target, [1.5, 2, 1.5]), color: [0.6, 0.6, 0.6] });
    buildLights(); drawMarkers(); changed(false);
  });
  on('remove-light', 'click', () => {
    if ((S.scene.light || []).length === 0) return;
    S.scene.light.pop();
    buildLights(); drawMarkers(); changed(false);
  });
  for (const v of ['render', 'terms', 'compare', 'lobe', 'fit', 'shader']) {
    on(`view-${v}`, 'click', () => setView(v));
  }
  on('fit-target', 'change', (e) => { S.fitTarget = e.target.files[0] || null; $('fit-result').textContent = S.fitTarget ? `target: ${S.fitTarget.name}` : ''; });
  on('fit-run', 'click', runFit);
  on('fit-apply', 'click', () => {
    if (!S.fitted) return;
    obj().material = clone(S.fitted);
    syncControls();
    setView('render');
  });
  on('compare-with', 'change', (e) => { S.compare = e.target.value; changed(false); });
  on('shader-target', 'change', () => changed(false));
  for (const k of ['vertex', 'fragment']) {
    on(`copy-${k}`, 'click', async () => {
      const text = $(`shader-${k}`).textContent;
      try { await navigator.clipboard.writeText(text); } catch {
        const r = document.createRange(); r.selectNodeContents($(`shader-${k}`));
        const sel = getSelection(); sel.removeAllRanges(); sel.addRange(r); document.execCommand('copy');
      }
      $('status').textContent = `${k} shader copied`;
    });
  }
  on('compare-split', 'input', (e) => { S.split = Number(e.target.value); drawCompare(); saveUrl(); });
  on('compare-difference', 'change', (e) => { S.difference = e.target.checked; renderCompare(); saveUrl(); });
  on('download-toml', 'click', downloadToml);
  on('download-png', 'click', downloadPng);
  on('load-model', 'change', (e) => loadFiles([...e.target.files]));
  const vp = $('viewport');
  vp.addEventListener('pointerdown', onViewportDown);
  vp.addEventListener('wheel', onWheel, { passive: false });
  vp.addEventListener('dragover', (e) => { e.preventDefault(); vp.classList.add('dragover'); });
  vp.addEventListener('dragleave', () => vp.classList.remove('dragover'));
  vp.addEventListener('drop', (e) => { e.preventDefault(); vp.classList.remove('dragover'); loadFiles([...e.dataTransfer.files]); });
  window.addEventListener('resize', () => { drawMarkers(); if (!S.size) changed(false); });
}

// One light's controls: type, colour (or per-term colours), position or direction,
// attenuation, spot cutoff and exponent; labels are their accessible names.
function buildLights() {
  const list = $('light-list');
  const focused = document.activeElement && document.activeElement.id;
  list.innerHTML = '';
  (S.scene.light || []).forEach((l, i) => {
    const n = i + 1;
    const div = document.createElement('div');
    div.className = 'light';
    const id = (k) => `light-${n}-${k}`;
    const row = (k, label, input) => `<div class="row"><label for="${id(k)}">Light ${n} ${label}</label>${input}<span class="err" data-for="${id(k)}"></span></div>`;
    const perTerm = l.ambient !== undefined || l.diffuse !== undefined || l.specular !== undefined;
    let html = `<h3>Light ${n}</h3>`;
    html += row('type', 'type', `<select id="${id('type')}">${['directional', 'point', 'spot'].map((t) => `<option value="${t}"${t === l.type ? ' selected' : ''}>${t}</option>`).join('')}</select>`);
    html += row('per-term', 'per-term colours', `<input type="checkbox" id="${id('per-term')}"${perTerm ? ' checked' : ''}>`);
    if (perTerm) {
      for (const k of ['ambient', 'diffuse', 'specular']) {
        const d = l[k] || (k === 'ambient' ? [0, 0, 0] : l.color || [1, 1, 1]);
        html += row(k, k, `<input type="color" id="${id(k)}" value="${hex(d)}">`);
      }
    } else {
      html += row('color', 'color', `<input type="color" id="${id('color')}" value="${hex(l.color || [1, 1, 1])}">`);
    }
    const txt = (k, v) => row(k, k, `<input type="text" id="${id(k)}" value="${v.map((x) => String(Math.round(x * 1e4) / 1e4)).join(', ')}">`);
    if (l.type !== 'directional') html += txt('position', l.position || [0, 0, 0]);
    if (l.type !== 'point') html += txt('direction', l.direction || [0, -1, 0]);
    if (l.type !== 'directional') html += txt('attenuation', l.attenuation || [1, 0, 0]);
    if (l.type === 'spot') {
      html += row('cutoff', 'cutoff', `<input type="number" id="${id('cutoff')}" min="0" max="90" step="any" value="${l.cutoff !== undefined ? l.cutoff : 30}">`);
      html += row('exponent', 'exponent', `<input type="number" id="${id('exponent')}" min="0" step="any" value="${l.exponent || 0}">`);
    }
    div.innerHTML = html;
    list.appendChild(div);
    const el = (k) => div.querySelector('#' + id(k));
    el('type').addEventListener('change', (e) => {
      const t = e.target.value;
      const c = cam();
      if (t !== 'directional' && !l.position) l.position = add(c.target, [1.5, 2, 1.5]);
      if (t !== 'point' && !l.direction) l.direction = l.position ? unit(sub(c.target, l.position)) : [0, -1, 0];
      if (t === 'spot' && l.cutoff === undefined) l.cutoff = 30;
      l.type = t;
      if (t === 'directional') { delete l.position; delete l.attenuation; }
      if (t === 'point') delete l.direction;
      if (t !== 'spot') { delete l.cutoff; delete l.exponent; }
      buildLights(); drawMarkers(); changed(false);
    });
    el('per-term').addEventListener('change', (e) => {
      if (e.target.checked) { const c = l.color || [1, 1, 1]; l.ambient = [0, 0, 0]; l.diffuse = c; l.specular = c; delete l.color; }
      else { l.color = l.diffuse || [1, 1, 1]; delete l.ambient; delete l.diffuse; delete l.specular; }
      buildLights(); changed(false);
    });
    for (const k of ['color', 'ambient', 'diffuse', 'specular']) {
      if (el(k)) el(k).addEventListener('input', (e) => { l[k] = unhex(e.target.value); drawMarkers(); changed(true); });
    }
    for (const k of ['position', 'direction', 'attenuation']) {
      if (!el(k)) continue;
      el(k).addEventListener('change', (e) => {
        const v = parseVec(e.target.value, 3);
        const slot = div.querySelector(`.err[data-for="${id(k)}"]`);
        if (!v) {
          slot.textContent = `expected 3 numbers, as "x, y, z"; got "${e.target.value}"`;
          e.target.classList.add('invalid');
          $('error').textContent = `light[${i}].${k}: expected 3 numbers`;
          return;
        }
        l[k] = v;
        drawMarkers(); changed(false);
      });
    }
    for (const k of ['cutoff', 'exponent']) {
      if (!el(k)) continue;
      el(k).addEventListener('change', (e) => {
        const v = Number(e.target.value);
        const slot = div.querySelector(`.err[data-for="${id(k)}"]`);
        if (e.target.value.trim() === '' || !Number.isFinite(v)) {
          slot.textContent = `expected a number, got "${e.target.value}"`;
          e.target.classList.add('invalid');
          return;
        }
        l[k] = v;
        changed(false);
      });
    }
  });
  if (focused && $(focused)) $(focused).focus();
}

function setView(v) {
  S.view = v;
  for (const k of ['render', 'terms', 'compare', 'lobe', 'fit', 'shader']) {
    $(`${k}-view`).hidden = k !== v;
    $(`view-${k}`).setAttribute('aria-pressed', String(k === v));
  }
  changed(false);
}

// ---------- the shader view ----------
// The images at the width they are shown at, in device pixels, at the frame's aspect.
function shaderSize() {
  const [fw, fh] = frameSize();
  const w = Math.max(32, Math.round($('shader-phong').parentElement.clientWidth * devicePixelRatio));
  return [w, Math.max(18, Math.round(w * fh / fw))];
}

// The pixels of an image source (img or canvas) as RGBA bytes at w x h.
function pixelsOf(source, w, h) {
  const c = document.createElement('canvas');
  c.width = w; c.height = h;
  const g = c.getContext('2d');
  g.drawImage(source, 0, 0);
  return g.getImageData(0, 0, w, h).data;
}

async function renderShader() {
  const g = generation;
  const [w, h] = shaderSize();
  const s = sceneFor(false, (s) => { s.image.width = w; s.image.height = h; s.image.antialias = 1; });
  $('shader-view').style.setProperty('--aspect', `${w} / ${h}`);
  hooks.active++;
  try {
    const target = $('shader-target').value;
    const code = await (await post(`/api/shader?target=${target}&object=${S.sel}`, s)).json();
    if (g !== generation) return;
    $('shader-vertex').textContent = code.vertex;
    $('shader-fragment').textContent = code.fragment;
    const page = await (await post('/api/shader?target=html', s)).text();
    const png = await (await post('/api/render', s)).blob();
    if (g !== generation) return;
    const img = $('shader-phong');
    img.src = URL.createObjectURL(png);
    await img.decode();
    const frame = $('shader-webgl');
    await new Promise((done) => { frame.onload = done; frame.srcdoc = page; });
    const win = frame.contentWindow;
    if (win.phongError) throw { error: `WebGL2: ${win.phongError}` };
    const ours = pixelsOf(img, w, h);
    const theirs = pixelsOf(win.document.getElementById('phong'), w, h);
    const diff = $('shader-diff');
    diff.width = w; diff.height = h;
    const out = new ImageData(w, h);
    let off = 0;
    for (let i = 0; i < w * h; i++) {
      let worst = 0;
      for (let k = 0; k < 3; k++) {
        const d = Math.abs(ours[4 * i + k] - theirs[4 * i + k]);
        worst = Math.max(worst, d);
        out.data[4 * i + k] = Math.min(255, d * 8);
      }
      out.data[4 * i + 3] = 255;
      if (worst > 2) off++;
    }
    diff.getContext('2d').putImageData(out, 0, 0);
    window.phong.shaderDifference = { width: w, height: h, off };
    $('shader-summary').textContent = `${off} of ${w * h} pixels differ by more than 2/255 (triangle edges: each rasteriser's own rule)`;
    clearErrors();
  } catch (e) {
    showError(e.error ? e : { error: String(e) });
  } finally {
    hooks.active--;
  }
}

// ---------- the fit ----------
async function runFit() {
  const slot = document.querySelector('.err[data-for="fit-target"]');
  slot.textContent = '';
  if (!S.fitTarget) { slot.textContent = 'choose a target image first'; return; }
  try {
    const bitmap = await createImageBitmap(S.fitTarget);
    const target = await blobBase64(S.fitTarget);
    // The scene at the target's size (the same camera: its aspect is the image's).
    const scene = sceneFor(false, (s) => { s.image.width = bitmap.width; s.image.height = bitmap.height; });
    bitmap.close();
    $('fit-result').textContent = 'fitting…';
    const r = await post('/api/fit', { scene, object: S.sel, target, free: $('fit-free').value });
    const f = await r.json();
    hooks.fit = f;
    S.fitted = f.material;
    $('fit-picture').src = 'data:image/png;base64,' + f.comparison;
    const m = f.material;
    $('fit-result').textContent = [
      `target | fit | 4×|difference|, ${f.pixels} pixels fitted`,
      `ambient   ${vfmt(m.ambient, 4)}`, `diffuse   ${vfmt(m.diffuse, 4)}`, `specular  ${vfmt(m.specular, 4)}`,
      `emission  ${vfmt(m.emission, 4)}`, `shininess ${fmt(m.shininess, 2)}`,
      `rmse ${fmt(f.rmse, 5)} (linear), psnr ${fmt(f.psnr, 2)} dB; nearest classic material ${f.nearest.name} (rmse ${fmt(f.nearest.rmse, 5)})`,
      ...f.undetermined.map((u) => 'undetermined: ' + u),
    ].join('\n');
    $('fit-apply').disabled = false;
  } catch (e) {
    slot.textContent = e.error || String(e);
    $('fit-result').textContent = '';
  }
}

// ---------- files ----------
function download(name, blob) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

async function downloadToml() {
  try {
    const r = await post('/api/toml', sceneFor(false));
    const text = await r.text();
    hooks.lastToml = text;
    download('scene.toml', new Blob([text], { type: 'application/toml' }));
  } catch (e) { showError(e.error ? e : { error: String(e) }); }
}

async function downloadPng() {
  try {
    const r = await post('/api/render', sceneFor(false));
    download('scene.png', await r.blob());
  } catch (e) { showError(e.error ? e : { error: String(e) }); }
}

async function loadFiles(files) {
  // MTL libraries, glTF buffers and texture images first, so that the model finds them when it
  // is parsed.
  const aside = (f) => (/\.(mtl|bin|png|jpe?g|tga|bmp)$/i.test(f.name) ? -1 : 0);
  files.sort((a, b) => aside(a) - aside(b));
  let objInfo = null;
  for (const f of files) {
    try {
      const r = await fetch(`/api/models/${encodeURIComponent(f.name)}`, { method: 'PUT', headers: { 'X-Phong-Client': CLIENT }, body: f });
      const info = await r.json();
      if (!r.ok) throw info;
      if (info.scene) objInfo = info;
    } catch (e) {
      const message = `${f.name}: ${e.error || e}`;
      document.querySelector('.err[data-for="load-model"]').textContent = message;
      $('error').textContent = message;
      return;
    }
  }
  document.querySelector('.err[data-for="load-model"]').textContent = '';
  if (!objInfo) { $('status').textContent = 'uploaded ' + files.map((f) => f.name).join(', '); return; }
  if (!S.models.includes(objInfo.name)) S.models.push(objInfo.name);
  // As `phong render MODEL.obj`: the model alone, framed, with its materials and lights.
  S.scene = objInfo.scene;
  S.original = clone(objInfo.scene);
  S.sel = 0;
  syncControls();
  $('status').textContent = `loaded ${objInfo.name}: ${objInfo.triangles} triangles in ${objInfo.parts} parts`;
  hooks.loaded = { name: objInfo.name, triangles: objInfo.triangles, parts: objInfo.parts };
  changed(false);
}

// ---------- the URL holds the state ----------
function saveUrl() {
  const state = { scene: S.scene, sel: S.sel, view: S.view, compare: S.compare, split: S.split, difference: S.difference };
  history.replaceState(null, '', location.pathname + location.search + '#' + encodeURIComponent(JSON.stringify(state)));
}

async function start() {
  const q = new URLSearchParams(location.search);
  S.previewScale = q.get('preview') === 'full' ? 1 : 0.5;
  const m = /^(\d+)x(\d+)$/.exec(q.get('size') || '');
  if (m) {
    // A fixed image size, shown at its own size where it fits (no scaling in the browser).
    S.size = [Number(m[1]), Number(m[2])];
    $('viewport').style.aspectRatio = `${S.size[0]} / ${S.size[1]}`;
    $('viewport').style.maxWidth = `${S.size[0]}px`;
  }
  const [mats, initial] = await Promise.all([fetch('/api/materials').then((r) => r.json()), fetch('/api/scene').then((r) => r.json())]);
  S.materials = mats;
  S.models = initial.models.slice();
  S.scene = initial.scene;
  S.original = clone(initial.scene);
  if (location.hash.length > 1) {
    try {
      const st = JSON.parse(decodeURIComponent(location.hash.slice(1)));
      if (st.scene && Array.isArray(st.scene.object)) S.scene = st.scene;
      Object.assign(S, { sel: Math.min(st.sel || 0, S.scene.object.length - 1), view: st.view || 'render', compare: st.compare || S.compare, split: st.split ?? 50, difference: !!st.difference });
    } catch (e) {
      $('error').textContent = 'the link\'s state could not be read: ' + e;
    }
  }
  if (!S.scene.object || S.scene.object.length === 0) S.scene.object = [{ shape: 'sphere' }];
  for (const o of S.scene.object) if (o.mesh && !S.models.includes(o.mesh)) S.models.push(o.mesh);
  $('compare-with').value = S.compare;
  $('compare-split').value = S.split;
  $('compare-difference').checked = S.difference;
  bindControls();
  syncControls();
  setView(S.view);
  hooks.ready = true;
}

start().catch((e) => { $('error').textContent = 'the page could not start: ' + e; });
