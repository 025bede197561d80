// The compute rasterizer: the whole frame in compute passes, on every core of the GPU.
//
// Some GPUs run the graphics pipeline's stages on a few of their cores (an H100 has two
// graphics-capable TPCs of 66): there this path is many times faster. It is the CPU
// renderer's arithmetic: vertices snapped to 1/256 pixel, edge functions in 64-bit integers
// with the top-left rule, its sample patterns (1, 4 or 16 per pixel), the nearest depth per
// sample (the first triangle on ties, as GL_LESS in draw order), then the same vertex and
// fragment stages as the pipeline (frame.wgsl), interpolated perspective-correctly at the
// pixel's centre once per visible triangle, and the CPU's resolve.
//
// 1. cs_vertex: per vertex, window position and (Gouraud, flat) colours.
// 2. cs_raster: per triangle; small ones test their pixels here, large ones reserve one item
//    per 16×16 tile of their box and are listed.
// 3. cs_args: the indirect dispatches of the next two. 4. cs_expand: one workgroup per large
//    triangle writes its items. 5. cs_tiles: one workgroup per item tests its pixels.
//    Both tests keep max(~depth << 32 | ~triangle) per pixel (64-bit atomic max).
// 6. cs_shade (cs_shade_samples with several samples): per pixel, the visible triangles'
//    barycentrics, the fragment stage, the resolve, the image.

struct Raster {
    // x: width, y: height, z: vertices, w: triangles.
    size: vec4<u32>,
    // Premultiplied background (what the pipeline clears to).
    background: vec4<f32>,
    // x: item capacity; y: samples per pixel (1, 4 or 16).
    items: vec4<u32>,
    // The sample offsets' bounds in 1/256 pixel: min x, max x, min y, max y.
    span: vec4<i32>,
    // The CPU renderer's sample pattern: offsets within the pixel in 1/256 (x, y).
    pattern: array<vec4<i32>, 16>,
}

struct Colors {
    color: vec4<f32>,
    color_back: vec4<f32>,
    flat_color: vec4<f32>,
    flat_back: vec4<f32>,
}

@group(0) @binding(3) var<uniform> raster: Raster;
// GpuVertex: position, normal, centroid, uv (two sets), color, tangent (20 floats).
@group(0) @binding(4) var<storage, read> vertices: array<f32>;
@group(0) @binding(5) var<storage, read> vertex_object: array<u32>;
@group(0) @binding(6) var<storage, read> indices: array<u32>;
// Per vertex: snapped x, y (1/256 pixel, i32 bits), window depth, 1/w (f32 bits).
@group(0) @binding(7) var<storage, read_write> projected: array<vec4<u32>>;
@group(0) @binding(8) var<storage, read_write> colors: array<Colors>;
@group(0) @binding(9) var<storage, read_write> visibility: array<atomic<u64>>;
@group(0) @binding(10) var<storage, read_write> items: array<vec2<u32>>;
// [0]: items reserved (may exceed the capacity); [1]: large triangles listed; [2]: 1 when a
// triangle's items did not fit (then the frame is drawn again by the pipeline; [0] alone
// could wrap around).
@group(0) @binding(11) var<storage, read_write> counter: array<atomic<u32>>;
@group(0) @binding(12) var<storage, read_write> dispatch: array<u32>;
// The visibility buffer's words (samples of a pixel together), for clearing and shading.
@group(0) @binding(13) var<storage, read_write> visibility_words: array<vec2<u32>>;
@group(0) @binding(14) var image: texture_storage_2d<rgba16float, write>;
// Large triangles: triangle, first item, first tile (x | y << 16), tiles across | down << 16.
@group(0) @binding(15) var<storage, read_write> large: array<vec4<u32>>;

const SUBPIXEL: i64 = 256li;
const HALF: i64 = 128li;
// A triangle whose pixel box holds more than this many pixels is split into 16×16 tiles.
const SMALL_BOX: i32 = 512;
const TILE: i32 = 16;
const MAX_GROUPS: u32 = 65535u;

fn load_vec3(v: u32, k: u32) -> vec3<f32> {
    let b = v * 20u + k * 3u;
    return vec3<f32>(vertices[b], vertices[b + 1u], vertices[b + 2u]);
}

// `round(v)` half away from zero, as the CPU's round_i64 (|v| < 2^23 here).
fn round_away(v: f32) -> i32 {
    let r = i32(floor(abs(v) + 0.5));
    return select(r, -r, v < 0.0);
}

// The linear id of a thread of a dispatch whose workgroups were laid out by `groups` on the host.
fn linear_id(gid: vec3<u32>, nwg: vec3<u32>, size: u32) -> u32 {
    return gid.x + gid.y * nwg.x * size;
}

@compute @workgroup_size(64)
fn cs_clear(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_id(gid, nwg, 64u);
    if (i == 0u) {
        atomicStore(&counter[0], 0u);
        atomicStore(&counter[1], 0u);
        atomicStore(&counter[2], 0u);
    }
    if (i < raster.size.x * raster.size.y * raster.items.y) {
        visibility_words[i] = vec2<u32>(0u);
    }
}

@compute @workgroup_size(64)
fn cs_vertex(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = linear_id(gid, nwg, 64u);
    if (v >= raster.size.z) {
        return;
    }
    let object = vertex_object[v];
    let out = vertex(load_vec3(v, 0u), load_vec3(v, 1u), load_vec3(v, 2u), object);
    // The CPU's projection (raster.rs `project`): the host made sure w > 0 and the window
    // coordinates are within ±32768 pixels.
    let c = frame.clip_from_world * vec4<f32>(load_vec3(v, 0u), 1.0);
    let iw = 1.0 / c.w;
    let w = f32(raster.size.x);
    let h = f32(raster.size.y);
    let sx = (c.x * iw * 0.5 + 0.5) * w;
    let sy = (0.5 - c.y * iw * 0.5) * h;
    let z = c.z * iw * 0.5 + 0.5;
    projected[v] = vec4<u32>(
        bitcast<u32>(round_away(sx * 256.0)),
        bitcast<u32>(round_away(sy * 256.0)),
        bitcast<u32>(z),
        bitcast<u32>(iw),
    );
    if (objects[object].options.mode.x < 2u) {
        colors[v] = Colors(
            vec4<f32>(out.color, 0.0),
            vec4<f32>(out.color_back, 0.0),
            vec4<f32>(out.flat_color, 0.0),
            vec4<f32>(out.flat_back, 0.0),
        );
    }
}

// A triangle set up as the CPU's `setup_edges`: vertices counter-clockwise on screen, edge i
// (opposite vertex i) E_i(X, Y) = a_i·X + b_i·Y + c_i in 1/256 pixel, positive inside.
struct Setup {
    valid: bool,
    front: bool,
    // Input vertex (0, 1, 2) of each set-up vertex.
    order: vec3<u32>,
    a0: i64, a1: i64, a2: i64,
    b0: i64, b1: i64, b2: i64,
    c0: i64, c1: i64, c2: i64,
    // 1 where the edge is not top-left (inside is E − 1 ≥ 0).
    bias: vec3<i32>,
    area: i64,
    // Pixel box: min inclusive, max exclusive.
    box_min: vec2<i32>,
    box_max: vec2<i32>,
    // Window depth of each set-up vertex.
    z: vec3<f32>,
}

fn xy_of(v: u32) -> vec2<i32> {
    let p = projected[v];
    return vec2<i32>(bitcast<i32>(p.x), bitcast<i32>(p.y));
}

fn setup(t: u32) -> Setup {
    var s: Setup;
    s.valid = false;
    let i0 = indices[3u * t];
    let i1 = indices[3u * t + 1u];
    let i2 = indices[3u * t + 2u];
    let p0 = xy_of(i0);
    let p1 = xy_of(i1);
    let p2 = xy_of(i2);
    let area = i64(p1.x - p0.x) * i64(p2.y - p0.y) - i64(p2.x - p0.x) * i64(p1.y - p0.y);
    if (area == 0li) {
        return s;
    }
    // Counter-clockwise in NDC (y up) is clockwise on screen (y down): area < 0 is front-facing.
    s.front = area < 0li;
    let two_sided = objects[vertex_object[i0]].options.flags.z != 0u;
    if (!s.front && !two_sided) {
        return s;
    }
    var q0 = p0;
    var q1 = p1;
    var q2 = p2;
    s.order = vec3<u32>(0u, 1u, 2u);
    if (s.front) {
        q1 = p2;
        q2 = p1;
        s.order = vec3<u32>(0u, 2u, 1u);
    }
    let lo = min(q0, min(q1, q2));
    let hi = max(q0, max(q1, q2));
    // The first pixel with a sample at or right of the minimum, the last with one at or left
    // of the maximum (arithmetic shifts round down, negatives included).
    let span_min = raster.span.xz;
    let span_max = raster.span.yw;
    s.box_min = max((lo - span_max + vec2<i32>(255)) >> vec2<u32>(8u), vec2<i32>(0));
    s.box_max = min(((hi - span_min) >> vec2<u32>(8u)) + vec2<i32>(1), vec2<i32>(raster.size.xy));
    if (any(s.box_min >= s.box_max)) {
        return s;
    }
    // Edge i from vertex j to vertex k: a = −(yb − ya), b = xb − xa, c = −(a·xa + b·ya).
    s.a0 = i64(q1.y) - i64(q2.y);
    s.b0 = i64(q2.x) - i64(q1.x);
    s.c0 = -(s.a0 * i64(q1.x) + s.b0 * i64(q1.y));
    s.a1 = i64(q2.y) - i64(q0.y);
    s.b1 = i64(q0.x) - i64(q2.x);
    s.c1 = -(s.a1 * i64(q2.x) + s.b1 * i64(q2.y));
    s.a2 = i64(q0.y) - i64(q1.y);
    s.b2 = i64(q1.x) - i64(q0.x);
    s.c2 = -(s.a2 * i64(q0.x) + s.b2 * i64(q0.y));
    // Top edge: horizontal, going right; left edge: going up (y down). Both inclusive.
    s.bias = vec3<i32>(
        select(1, 0, (q1.y == q2.y && q2.x > q1.x) || q2.y < q1.y),
        select(1, 0, (q2.y == q0.y && q0.x > q2.x) || q0.y < q2.y),
        select(1, 0, (q0.y == q1.y && q1.x > q0.x) || q1.y < q0.y),
    );
    s.area = select(area, -area, area < 0li);
    let ids = vec3<u32>(i0, i1, i2);
    s.z = vec3<f32>(
        bitcast<f32>(projected[ids[s.order.x]].z),
        bitcast<f32>(projected[ids[s.order.y]].z),
        bitcast<f32>(projected[ids[s.order.z]].z),
    );
    s.valid = true;
    return s;
}

// The edge functions at a point of pixel `p` (offset `o` in 1/256), and whether it is covered.
struct Edges {
    e0: i64,
    e1: i64,
    e2: i64,
    covered: bool,
}

fn edges_at(s: Setup, p: vec2<i32>, o: vec2<i32>) -> Edges {
    let x = i64(p.x) * SUBPIXEL + i64(o.x);
    let y = i64(p.y) * SUBPIXEL + i64(o.y);
    var e: Edges;
    e.e0 = s.a0 * x + s.b0 * y + s.c0;
    e.e1 = s.a1 * x + s.b1 * y + s.c1;
    e.e2 = s.a2 * x + s.b2 * y + s.c2;
    e.covered = e.e0 - i64(s.bias.x) >= 0li && e.e1 - i64(s.bias.y) >= 0li && e.e2 - i64(s.bias.z) >= 0li;
    return e;
}

// Depth test of triangle `t` at each sample of pixel `p`: the nearest depth, then the lowest
// triangle, wins.
fn test_pixel(s: Setup, t: u32, p: vec2<i32>) {
    let inv = 1.0 / f32(s.area);
    let ns = raster.items.y;
    let base = (u32(p.y) * raster.size.x + u32(p.x)) * ns;
    for (var k = 0u; k < ns; k++) {
        let e = edges_at(s, p, raster.pattern[k].xy);
        if (!e.covered) {
            continue;
        }
        let z = clamp(f32(e.e0) * inv * s.z.x + f32(e.e1) * inv * s.z.y + f32(e.e2) * inv * s.z.z, 0.0, 1.0);
        let key = (u64(~bitcast<u32>(z)) << 32u) | u64(~t);
        atomicMax(&visibility[base + k], key);
    }
}

@compute @workgroup_size(64)
fn cs_raster(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let t = linear_id(gid, nwg, 64u);
    if (t >= raster.size.w) {
        return;
    }
    let s = setup(t);
    if (!s.valid) {
        return;
    }
    let extent = s.box_max - s.box_min;
    if (extent.x * extent.y <= SMALL_BOX) {
        for (var y = s.box_min.y; y < s.box_max.y; y++) {
            for (var x = s.box_min.x; x < s.box_max.x; x++) {
                test_pixel(s, t, vec2<i32>(x, y));
            }
        }
        return;
    }
    let t0 = vec2<u32>(s.box_min / TILE);
    let span = vec2<u32>((s.box_max - vec2<i32>(1)) / TILE) - t0 + vec2<u32>(1u);
    let n = span.x * span.y;
    let first = atomicAdd(&counter[0], n);
    if (first > raster.items.x || n > raster.items.x - first) {
        atomicStore(&counter[2], 1u);
        return;
    }
    // Every large triangle has at least two tiles, so no more than capacity / 2 are listed.
    let b = atomicAdd(&counter[1], 1u);
    large[b] = vec4<u32>(t, first, t0.x | (t0.y << 16u), span.x | (span.y << 16u));
}

// Workgroups for `n` groups' worth of work, at most MAX_GROUPS across (read back as
// wid.x + wid.y · MAX_GROUPS).
fn write_args(at: u32, n: u32) {
    dispatch[at] = min(n, MAX_GROUPS);
    dispatch[at + 1u] = (n + MAX_GROUPS - 1u) / MAX_GROUPS;
    dispatch[at + 2u] = 1u;
}

@compute @workgroup_size(1)
fn cs_args() {
    write_args(0u, atomicLoad(&counter[1]));
    write_args(4u, min(atomicLoad(&counter[0]), raster.items.x));
}

@compute @workgroup_size(256)
fn cs_expand(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let b = wid.x + wid.y * MAX_GROUPS;
    if (b >= atomicLoad(&counter[1])) {
        return;
    }
    let e = large[b];
    let t0 = vec2<u32>(e.z & 0xffffu, e.z >> 16u);
    let span = vec2<u32>(e.w & 0xffffu, e.w >> 16u);
    for (var j = lid; j < span.x * span.y; j += 256u) {
        let tile = t0 + vec2<u32>(j % span.x, j / span.x);
        items[e.y + j] = vec2<u32>(e.x, tile.x | (tile.y << 16u));
    }
}

@compute @workgroup_size(16, 16)
fn cs_tiles(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let k = wid.x + wid.y * MAX_GROUPS;
    if (k >= min(atomicLoad(&counter[0]), raster.items.x)) {
        return;
    }
    let item = items[k];
    let t = item.x;
    let s = setup(t);
    let tile = vec2<i32>(i32(item.y & 0xffffu), i32(item.y >> 16u));
    let p = tile * TILE + vec2<i32>(lid.xy);
    if (any(p < s.box_min) || any(p >= s.box_max)) {
        return;
    }
    test_pixel(s, t, p);
}

// The colour of visible triangle `t` at pixel `p`'s centre (shading once per pixel, as the
// CPU renderer, whichever of its samples the triangle covers).
fn color_of(t: u32, p: vec2<i32>) -> vec3<f32> {
    let s = setup(t);
    let e = edges_at(s, p, vec2<i32>(128));
    let ids = vec3<u32>(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]);
    let v = vec3<u32>(ids[s.order.x], ids[s.order.y], ids[s.order.z]);
    // Perspective-correct weights: λ_i/w_i normalised (the area cancels).
    let iw = vec3<f32>(
        bitcast<f32>(projected[v.x].w),
        bitcast<f32>(projected[v.y].w),
        bitcast<f32>(projected[v.z].w),
    );
    let inv = 1.0 / f32(s.area);
    let l = vec3<f32>(f32(e.e0), f32(e.e1), f32(e.e2)) * inv * iw;
    let k = l / (l.x + l.y + l.z);
    var f: VsOut;
    f.world = k.x * load_vec3(v.x, 0u) + k.y * load_vec3(v.y, 0u) + k.z * load_vec3(v.z, 0u);
    f.normal = k.x * load_vec3(v.x, 1u) + k.y * load_vec3(v.y, 1u) + k.z * load_vec3(v.z, 1u);
    f.object = vertex_object[ids.x];
    let mode = objects[f.object].options.mode.x;
    if (mode == 1u) {
        let c0 = colors[v.x];
        let c1 = colors[v.y];
        let c2 = colors[v.z];
        f.color = k.x * c0.color.xyz + k.y * c1.color.xyz + k.z * c2.color.xyz;
        f.color_back = k.x * c0.color_back.xyz + k.y * c1.color_back.xyz + k.z * c2.color_back.xyz;
    } else if (mode == 0u) {
        // The provoking (first) vertex's colour; flat objects' three vertices hold the same.
        f.flat_color = colors[ids.x].flat_color.xyz;
        f.flat_back = colors[ids.x].flat_back.xyz;
    }
    return fragment(f, !s.front);
}

@compute @workgroup_size(8, 8)
fn cs_shade(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= raster.size.x || gid.y >= raster.size.y) {
        return;
    }
    let p = vec2<i32>(gid.xy);
    let key = visibility_words[gid.y * raster.size.x + gid.x];
    if (all(key == vec2<u32>(0u))) {
        textureStore(image, p, raster.background);
    } else {
        // Little-endian words: x holds ~triangle, y ~depth.
        textureStore(image, p, vec4<f32>(color_of(~key.x, p), 1.0));
    }
}

// cs_shade for several samples per pixel (its own entry point: the arrays below slowed the
// one-sample kernel from 0.25 to 0.45 ms of a 4K frame on an H100): each distinct triangle
// shaded once, then the CPU's resolve in sample order, alpha-weighted (background samples
// carry the background's alpha).
@compute @workgroup_size(8, 8)
fn cs_shade_samples(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= raster.size.x || gid.y >= raster.size.y) {
        return;
    }
    let p = vec2<i32>(gid.xy);
    let ns = raster.items.y;
    let base = (gid.y * raster.size.x + gid.x) * ns;
    var ids: array<u32, 16>;
    var cols: array<vec3<f32>, 16>;
    var distinct = 0u;
    let bg = raster.background;
    var acc = vec4<f32>(0.0);
    for (var k = 0u; k < ns; k++) {
        let key = visibility_words[base + k];
        if (all(key == vec2<u32>(0u))) {
            // Premultiplied: rgb · alpha, as the resolve sums.
            acc += bg;
            continue;
        }
        let t = ~key.x;
        var c = vec3<f32>(0.0);
        var found = false;
        for (var j = 0u; j < distinct; j++) {
            if (ids[j] == t) {
                c = cols[j];
                found = true;
                break;
            }
        }
        if (!found) {
            c = color_of(t, p);
            ids[distinct] = t;
            cols[distinct] = c;
            distinct++;
        }
        acc += vec4<f32>(c, 1.0);
    }
    // Premultiplied average; the read-back divides by alpha (straight alpha, as the CPU).
    textureStore(image, p, acc / f32(ns));
}
