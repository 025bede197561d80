// phong's illumination model in WGSL: a line-for-line port of phong_core::shade, which is the
// specification (see crates/phong-core/src/shading.rs). Tested against it in a compute pass
// (crates/phong-gpu/tests/gpu.rs). Structs mirror the #[repr(C)] types in src/gpu_types.rs.

struct Light {
    // x: 0 directional, 1 point, 2 spot; y: 1 when the spot cutoff is 180 (no cone).
    kind: vec4<u32>,
    // xyz: position (point, spot) or the unit vector towards the light (directional).
    position: vec4<f32>,
    // xyz: unit spot axis; w: cos(cutoff).
    direction: vec4<f32>,
    // xyz: ambient colour; w: spot exponent.
    ambient: vec4<f32>,
    diffuse: vec4<f32>,
    specular: vec4<f32>,
    // xyz: attenuation k0, k1, k2.
    attenuation: vec4<f32>,
}

struct Material {
    ambient: vec4<f32>,
    diffuse: vec4<f32>,
    specular: vec4<f32>,
    // xyz: emission; w: shininess.
    emission: vec4<f32>,
}

struct Options {
    // x: specular model (0 none, 1 Phong, 2 Blinn-Phong, 3 Lyon); y: Lyon squarings;
    // z: Lyon lambda (0 dot, 1 difference); w: normalization (0 none, 1 Phong, 2 Blinn-Phong, 3 exact).
    model: vec4<u32>,
    // x: gate specular; y: clamp; z: two-sided; w: viewer (0 local, 1 infinite).
    flags: vec4<u32>,
    // x: interpolation (0 flat, 1 Gouraud, 2 Phong); y: output (0 color, 1 ambient, 2 diffuse,
    // 3 specular, 4 normal, 5 depth).
    mode: vec4<u32>,
    // xyz: eye (local viewer) or direction towards the viewer (infinite).
    view: vec4<f32>,
}

struct ObjectParams {
    material: Material,
    options: Options,
}

struct Shading {
    ambient: vec3<f32>,
    diffuse: vec3<f32>,
    specular: vec3<f32>,
    color: vec3<f32>,
}

const PI: f32 = 3.14159265358979;
const F32_MAX: f32 = 3.40282347e38;

// glam's normalize_or_zero: v / |v|, or zero when |v| is zero or not finite.
fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let rcp = 1.0 / length(v);
    if (rcp > 0.0 && rcp <= F32_MAX) {
        return v * rcp;
    }
    return vec3<f32>(0.0);
}

// (x⁺)^s with 0^s = 0, x clamped to 1.
fn pow_positive(x: f32, s: f32) -> f32 {
    if (x > 0.0) {
        return pow(min(x, 1.0), s);
    }
    return 0.0;
}

fn lyon(lambda: f32, s: f32, squarings: u32) -> f32 {
    let n = min(squarings, 16u);
    let gamma = f32(1u << n);
    var t = max(1.0 - (s / gamma) * lambda, 0.0);
    for (var i = 0u; i < n; i++) {
        t = t * t;
    }
    return t;
}

fn specular_factor(o: Options, n: vec3<f32>, l: vec3<f32>, v: vec3<f32>, s: f32) -> f32 {
    switch o.model.x {
        case 1u: {
            let r = 2.0 * dot(l, n) * n - l;
            return pow_positive(dot(r, v), s);
        }
        case 2u: {
            let h = normalize_or_zero(l + v);
            if (all(h == vec3<f32>(0.0))) {
                return 0.0;
            }
            return pow_positive(dot(n, h), s);
        }
        case 3u: {
            let r = 2.0 * dot(l, n) * n - l;
            let rv = dot(r, v);
            if (rv <= 0.0) {
                return 0.0;
            }
            var lam = 1.0 - rv;
            if (o.model.z == 1u) {
                let d = r - v;
                lam = 0.5 * dot(d, d);
            }
            return lyon(max(lam, 0.0), s, o.model.y);
        }
        default: {
            return 0.0;
        }
    }
}

// (k_d, k_s) of the normalization.
fn normalization_factors(which: u32, s: f32) -> vec2<f32> {
    switch which {
        case 1u: { return vec2<f32>(1.0 / PI, (s + 2.0) / (2.0 * PI)); }
        case 2u: { return vec2<f32>(1.0 / PI, (s + 8.0) / (8.0 * PI)); }
        case 3u: { return vec2<f32>(1.0 / PI, (s + 2.0) * (s + 4.0) / (8.0 * PI * (exp2(-s / 2.0) + s))); }
        default: { return vec2<f32>(1.0, 1.0); }
    }
}

fn finite_or_zero(c: vec3<f32>) -> vec3<f32> {
    return clamp(c, vec3<f32>(-F32_MAX), vec3<f32>(F32_MAX));
}

fn shade(position: vec3<f32>, normal: vec3<f32>, m: Material, o: Options, ambient_light: vec3<f32>, light_count: u32) -> Shading {
    var v: vec3<f32>;
    if (o.flags.w == 0u) {
        v = normalize_or_zero(o.view.xyz - position);
    } else {
        v = normalize_or_zero(o.view.xyz);
    }
    var n = normalize_or_zero(normal);
    if (o.flags.z != 0u && dot(n, v) < 0.0) {
        n = -n;
    }
    let s = m.emission.w;
    let k = normalization_factors(o.model.w, s);
    let normalized = o.model.w != 0u;

    var amb = m.emission.xyz + m.ambient.xyz * ambient_light;
    var dif = vec3<f32>(0.0);
    var spe = vec3<f32>(0.0);
    for (var i = 0u; i < light_count; i++) {
        let li = lights[i];
        var to_light: vec3<f32>;
        var factor = 1.0;
        if (li.kind.x == 0u) {
            to_light = li.position.xyz;
        } else {
            let dv = li.position.xyz - position;
            let d = length(dv);
            if (d > 0.0) {
                to_light = dv / d;
            } else {
                to_light = vec3<f32>(0.0);
            }
            let a = li.attenuation;
            factor = 1.0 / (a.x + d * (a.y + d * a.z));
            if (li.kind.x == 2u && li.kind.y == 0u && d > 0.0) {
                let c = dot(-to_light, li.direction.xyz);
                if (c >= li.direction.w) {
                    factor = factor * pow(max(c, 0.0), li.ambient.w);
                } else {
                    factor = 0.0;
                }
            }
        }
        if (!(factor > 0.0 && factor <= F32_MAX)) {
            continue;
        }
        amb += m.ambient.xyz * li.ambient.xyz * factor;
        let l = to_light;
        if (all(l == vec3<f32>(0.0)) || all(n == vec3<f32>(0.0))) {
            continue;
        }
        let ndotl = dot(n, l);
        if (ndotl > 0.0) {
            dif += m.diffuse.xyz * li.diffuse.xyz * (factor * k.x * ndotl);
        } else if (o.flags.x != 0u) {
            continue;
        }
        if (all(v == vec3<f32>(0.0))) {
            continue;
        }
        var sp = specular_factor(o, n, l, v, s);
        if (normalized) {
            sp = sp * max(ndotl, 0.0);
        }
        if (sp > 0.0) {
            spe += m.specular.xyz * li.specular.xyz * (factor * k.y * sp);
        }
    }
    var out: Shading;
    out.ambient = finite_or_zero(amb);
    out.diffuse = finite_or_zero(dif);
    out.specular = finite_or_zero(spe);
    let sum = finite_or_zero(out.ambient + out.diffuse + out.specular);
    if (o.flags.y != 0u) {
        out.color = clamp(sum, vec3<f32>(0.0), vec3<f32>(1.0));
    } else {
        out.color = sum;
    }
    return out;
}

// The term of `sh` that `output` shows (normal and depth are handled by the caller).
fn term(output: u32, sh: Shading) -> vec3<f32> {
    switch output {
        case 1u: { return sh.ambient; }
        case 2u: { return sh.diffuse; }
        case 3u: { return sh.specular; }
        default: { return sh.color; }
    }
}
