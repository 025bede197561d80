//! The probe: what the renderer computes at one pixel, term by term, from phong-core's
//! [`shade`].
//!
//! The pixel's visible triangle is found by a ray through the pixel's centre (the ray's hit
//! barycentrics are the perspective-correct ones the rasteriser interpolates with). Back faces
//! are culled unless the object is two-sided; a two-sided back face is lit with its normals
//! flipped, as the renderers do. The lighting is then [`shade`] itself: once for the pixel's
//! value, and once per light alone (unclamped, without emission or global ambient) for the
//! per-light terms. A textured object's maps are sampled at the hit's texture coordinates
//! (their screen derivatives by central differences of rays on the triangle's plane)
//! and applied by [`shade_textured`] (per-pixel shading) or `Lit::modulate` (Gouraud, flat),
//! as the renderers do.

use glam::{DVec3, Vec2, Vec3};
use phong_core::mesh::facet_normal;
use phong_core::{
    Color, Interpolation, Light, Lighting, Lit, Maps, Material, Object, Output, Scene, Shading, ShadingOptions,
    SpecularModel, SurfacePoint, Texels, View, depth_color, normal_color, perturb, shade, shade_textured,
    specular_factor,
};
use serde::Serialize;

/// Everything the probe reports for a pixel.
#[derive(Debug, Serialize)]
pub struct Probe {
    /// The pixel, from the top-left corner.
    pub x: u32,
    /// The pixel's row.
    pub y: u32,
    /// The surface seen there; `None`: the background.
    pub hit: Option<Hit>,
    /// The pixel's value as the renderer writes it (linear colour, 0..1 where clamped).
    pub value: [f32; 3],
    /// `value` in the image's 8-bit encoding (the PNG's bytes).
    pub value8: [u8; 3],
    /// Notes on how the value relates to the image (antialiasing, Gouraud).
    pub notes: Vec<String>,
}

/// The surface point under a pixel.
#[derive(Debug, Serialize)]
pub struct Hit {
    /// Index in the scene's objects.
    pub object: usize,
    /// The object's name.
    pub name: String,
    /// Index of the triangle in the object's mesh.
    pub triangle: usize,
    /// Perspective-correct barycentric weights of the triangle's vertices.
    pub barycentric: [f32; 3],
    /// Whether the triangle is seen from its back (two-sided lighting flips its normals).
    pub back_face: bool,
    /// "flat", "gouraud" or "phong".
    pub interpolation: &'static str,
    /// "color", "ambient", ... as the object's `output`.
    pub output: &'static str,
    /// The shaded point `P` (for flat shading, the triangle's centroid).
    pub position: [f32; 3],
    /// The unit normal `N` used (after interpolation, and flipped on a back face).
    pub normal: [f32; 3],
    /// The unit view vector `V`.
    pub view: [f32; 3],
    /// The material.
    pub material: MaterialNumbers,
    /// Energy normalisation factors `(k_d, k_s)` (1, 1 without normalisation).
    pub normalization: [f32; 2],
    /// Whether the specular term is gated by `N·L > 0`.
    pub gate_specular: bool,
    /// Whether the sum is clamped to `[0, 1]`.
    pub clamp: bool,
    /// The specular model: "none", "phong", "blinn-phong" or "lyon".
    pub specular_model: &'static str,
    /// `e_m + a_m⊗a_g`: emission and the global ambient term.
    pub global_ambient: [f32; 3],
    /// The global ambient light `a_g`.
    pub ambient_light: [f32; 3],
    /// One entry per light.
    pub lights: Vec<LightTerms>,
    /// The terms summed over lights, from [`shade`] at this point.
    pub ambient: [f32; 3],
    /// Diffuse term.
    pub diffuse: [f32; 3],
    /// Specular term.
    pub specular: [f32; 3],
    /// `ambient + diffuse + specular`, before clamping.
    pub sum: [f32; 3],
    /// The colour: `sum`, clamped when the option is on.
    pub color: [f32; 3],
    /// Gouraud: the three vertices' lit values, which the pixel interpolates.
    pub vertices: Vec<VertexValue>,
    /// A textured object: the texture coordinates and what the maps give there.
    pub texture: Option<TextureValue>,
}

/// What a textured object's maps give at the probed point.
#[derive(Debug, Serialize)]
pub struct TextureValue {
    /// Texture coordinates.
    pub uv: [f32; 2],
    /// Their derivatives along the image's x and y, per pixel (the level of detail comes from
    /// them).
    pub uv_dx: [f32; 2],
    /// See `uv_dx`.
    pub uv_dy: [f32; 2],
    /// The diffuse map's RGBA (1 without one).
    pub diffuse: [f32; 4],
    /// The specular map's colour (1 without one; a metallic-roughness map's specular colour).
    pub specular: [f32; 3],
    /// The factor on the shininess (a shininess map's; a metallic-roughness map gives the
    /// shininess itself, its material's being 1).
    pub shininess: f32,
    /// The occlusion on the ambient terms (1 without an occlusion map).
    pub occlusion: f32,
    /// The point's alpha (material, diffuse map, alpha map).
    pub alpha: f32,
    /// Whether the alpha test discards the point.
    pub discarded: bool,
}

/// The material's numbers.
#[derive(Debug, Serialize)]
pub struct MaterialNumbers {
    /// `a_m`.
    pub ambient: [f32; 3],
    /// `d_m`.
    pub diffuse: [f32; 3],
    /// `s_m`.
    pub specular: [f32; 3],
    /// `e_m`.
    pub emission: [f32; 3],
    /// `s`.
    pub shininess: f32,
}

/// One light's part at the point.
#[derive(Debug, Serialize)]
pub struct LightTerms {
    /// "directional", "point" or "spot".
    pub kind: &'static str,
    /// Unit vector towards the light, `L`.
    pub l: [f32; 3],
    /// The reflection of `L`, `R = 2(L·N)N − L`.
    pub r: [f32; 3],
    /// The half vector `H = normalize(L + V)`.
    pub h: [f32; 3],
    /// `N·L`.
    pub n_dot_l: f32,
    /// `R·V`.
    pub r_dot_v: f32,
    /// `N·H`.
    pub n_dot_h: f32,
    /// Distance to a point or spot light.
    pub distance: Option<f32>,
    /// `1/(k0 + k1·d + k2·d²)` (1 for a directional light).
    pub attenuation: f32,
    /// The spot factor (1 for other lights, 0 outside the cone).
    pub spot: f32,
    /// The specular factor of the model (`(R·V)^s`, `(N·H)^s`, Lyon's), before gating.
    pub spec: f32,
    /// Whether the specular term counts (`N·L > 0`, or gating off).
    pub lit: bool,
    /// `att·spot·a_m⊗a_l`.
    pub ambient: [f32; 3],
    /// `att·spot·k_d·(N·L)⁺·d_m⊗d_l`.
    pub diffuse: [f32; 3],
    /// `att·spot·k_s·f·spec·s_m⊗s_l`.
    pub specular: [f32; 3],
    /// The light's colours `(a_l, d_l, s_l)`.
    pub colors: [[f32; 3]; 3],
}

/// Gouraud: one vertex's lit value.
#[derive(Debug, Serialize)]
pub struct VertexValue {
    /// Position.
    pub position: [f32; 3],
    /// Normal (flipped on a back face).
    pub normal: [f32; 3],
    /// The vertex's value of the object's output.
    pub value: [f32; 3],
}

fn c3(c: Color) -> [f32; 3] {
    [c.r, c.g, c.b]
}

fn v3(v: Vec3) -> [f32; 3] {
    v.to_array()
}

fn output_name(o: Output) -> &'static str {
    match o {
        Output::Color => "color",
        Output::Ambient => "ambient",
        Output::Diffuse => "diffuse",
        Output::Specular => "specular",
        Output::Normal => "normal",
        Output::Depth => "depth",
    }
}

/// The nearest front-facing (or two-sided) triangle along the ray through pixel `(x, y)`'s
/// centre: object, triangle, barycentrics, back face.
/// The ray through window point `(x, y)` (pixels): its start on the near plane and its
/// direction to the far plane.
fn ray(scene: &Scene, x: f64, y: f64) -> (DVec3, DVec3) {
    let (w, h) = (scene.image.width, scene.image.height);
    let m = scene.camera.clip_from_world(w as f32 / h as f32).as_dmat4().inverse();
    let ndc_x = 2.0 * x / f64::from(w) - 1.0;
    let ndc_y = 1.0 - 2.0 * y / f64::from(h);
    let near = m.project_point3(DVec3::new(ndc_x, ndc_y, -1.0));
    let far = m.project_point3(DVec3::new(ndc_x, ndc_y, 1.0));
    (near, far - near)
}

/// Barycentrics of the ray `(near, dir)`'s hit on the plane of triangle `[a, b, c]` (inside the
/// triangle or not); `None` where the ray runs along the plane.
fn plane_barycentrics((near, dir): (DVec3, DVec3), [a, b, c]: [DVec3; 3]) -> Option<[f64; 3]> {
    let (e1, e2) = (b - a, c - a);
    let pv = dir.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let s = near - a;
    let u = s.dot(pv) / det;
    let v = dir.dot(s.cross(e1)) / det;
    Some([1.0 - u - v, u, v])
}

fn trace(scene: &Scene, x: u32, y: u32) -> Option<(usize, usize, [f64; 3], bool)> {
    let (near, dir) = ray(scene, f64::from(x) + 0.5, f64::from(y) + 0.5);
    let mut best: Option<(f64, usize, usize, [f64; 3], bool)> = None;
    for (oi, obj) in scene.objects.iter().enumerate() {
        let two_sided = obj.shading.options.two_sided;
        let p = obj.mesh.positions();
        for (ti, t) in obj.mesh.triangles().iter().enumerate() {
            let [a, b, c] = t.map(|i| p[i as usize].as_dvec3());
            let (e1, e2) = (b - a, c - a);
            let pv = dir.cross(e2);
            let det = e1.dot(pv);
            if det == 0.0 || !det.is_finite() {
                continue;
            }
            // det = −dir·(e1 × e2): positive where the ray runs against the counter-clockwise
            // normal, a front face (OpenGL's rule).
            let back = det < 0.0;
            if back && !two_sided {
                continue;
            }
            let inv = 1.0 / det;
            let s = near - a;
            let u = s.dot(pv) * inv;
            let q = s.cross(e1);
            let v = dir.dot(q) * inv;
            let t_hit = e2.dot(q) * inv;
            if u < 0.0 || v < 0.0 || u + v > 1.0 || !(0.0..=1.0).contains(&t_hit) {
                continue;
            }
            if best.as_ref().is_none_or(|b| t_hit < b.0) {
                best = Some((t_hit, oi, ti, [1.0 - u - v, u, v], back));
            }
        }
    }
    best.map(|(_, o, t, b, back)| (o, t, b, back))
}

/// Probes pixel `(x, y)` of `scene` (inside the image: checked by the caller).
pub fn probe(scene: &Scene, x: u32, y: u32) -> Probe {
    let encoding = scene.image.encoding;
    let bg = scene.image.background;
    let mut notes = Vec::new();
    if scene.image.samples != phong_core::Samples::One {
        notes.push(format!(
            "antialias {}: the pixel averages {} samples; the probe is the surface at the pixel's centre",
            scene.image.samples, scene.image.samples
        ));
    }
    let Some((oi, ti, bary, back)) = trace(scene, x, y) else {
        let value = [bg[0], bg[1], bg[2]];
        return Probe {
            x,
            y,
            hit: None,
            value,
            value8: value.map(|c| encoding.encode(c)),
            notes,
        };
    };
    let obj = &scene.objects[oi];
    let mesh = &obj.mesh;
    let tri = mesh.triangles()[ti];
    let ps = tri.map(|i| mesh.positions()[i as usize]);
    let ns = [0, 1, 2].map(|k| mesh.corner_normal(ti, k));
    let b = bary.map(|w| w as f32);
    let lerp = |v: [Vec3; 3]| v[0] * b[0] + v[1] * b[1] + v[2] * b[2];
    let flip = if back { -1.0 } else { 1.0 };
    let view = scene.camera.view(obj.shading.viewer);
    let interpolation = obj.shading.interpolation;
    let output = obj.shading.output;
    // The point and normal the lighting is computed at.
    let (position, normal) = match interpolation {
        Interpolation::Flat => ((ps[0] + ps[1] + ps[2]) / 3.0, facet_normal(ps[0], ps[1], ps[2]) * flip),
        _ => (lerp(ps), lerp(ns) * flip),
    };
    let lit_output = !matches!(output, Output::Normal | Output::Depth);
    let texture = (obj.textured() && lit_output).then(|| texels_at(scene, obj, tri, bary, (x, y)));
    let texels = texture.map(|t| t.3);
    let options = ShadingOptions {
        two_sided: false,
        ..obj.shading.options
    };
    // A normal map tilts the interpolated normal in the mesh's tangent frame (per-pixel
    // shading only, as the renderers).
    let normal = match texels.and_then(|t| t.normal) {
        Some(ts) if interpolation == Interpolation::Phong && !mesh.tangents().is_empty() => {
            let tg = tri.map(|i| mesh.tangents()[i as usize]);
            perturb(normal, tg[0] * b[0] + tg[1] * b[1] + tg[2] * b[2], ts)
        }
        _ => normal,
    };
    let at = match &texels {
        Some(t) => shade_textured(
            &SurfacePoint { position, normal },
            &view,
            &obj.material,
            t,
            &scene.lighting,
            &options,
        ),
        None => obj.shade(&scene.lighting, &view, position, normal),
    };
    // Gouraud and flat textured: the light made per vertex or triangle, the texels per pixel.
    let modulate = |(p, s): (Color, Color), t: &Texels| {
        Lit {
            primary: p,
            specular: s,
            ..Lit::default()
        }
        .modulate(t, options.clamp)
    };
    let mut vertices = Vec::new();
    let value = match output {
        // Flat: the facet normal as it is; else the interpolated one, renormalised (as drawn).
        Output::Normal if interpolation == Interpolation::Flat => normal_color(normal),
        Output::Normal => normal_color(normal.normalize_or_zero()),
        Output::Depth => depth_color(&scene.camera, lerp(ps)),
        _ if interpolation == Interpolation::Flat && texels.is_some() => {
            let t = texels.as_ref().expect("textured");
            modulate(obj.vertex_light(&scene.lighting, &view, position, normal), t)
        }
        _ if interpolation == Interpolation::Gouraud => {
            let (mut c, mut spec) = (Color::BLACK, Color::BLACK);
            for k in 0..3 {
                let (v, s) = obj.vertex_light(&scene.lighting, &view, ps[k], ns[k] * flip);
                vertices.push(VertexValue {
                    position: v3(ps[k]),
                    normal: v3(ns[k] * flip),
                    value: c3(v),
                });
                c += v * b[k];
                spec += s * b[k];
            }
            if let Some(t) = &texels {
                c = modulate((c, spec), t);
            }
            notes.push(
                "Gouraud: the pixel interpolates the vertices' values; the terms below are the lighting at the \
                 pixel's own point, for comparison"
                    .into(),
            );
            c
        }
        _ => output.term(&at),
    };
    let value = c3(value);
    if obj.blends() {
        let alpha = texture
            .as_ref()
            .map_or(obj.material.alpha(), |t| Maps::alpha(&obj.material, &t.3));
        notes.push(format!(
            "blended: the pixel is this colour at alpha {alpha:.3} over what is behind it (drawn after the opaque objects, back to front)"
        ));
    }
    let hit = hit_terms(scene, obj, &view, position, normal, &at);
    let texture = texture.map(|(uv, d_dx, d_dy, t)| texture_value(obj, [uv, d_dx, d_dy], &t, &mut notes));
    Probe {
        x,
        y,
        hit: Some(Hit {
            object: oi,
            name: obj.name.clone(),
            triangle: ti,
            barycentric: b,
            back_face: back,
            interpolation: match interpolation {
                Interpolation::Flat => "flat",
                Interpolation::Gouraud => "gouraud",
                Interpolation::Phong => "phong",
            },
            output: output_name(output),
            vertices,
            texture,
            ..hit
        }),
        value,
        value8: value.map(|c| encoding.encode(c)),
        notes,
    }
}

/// The texels of `obj` at barycentrics `bary` of triangle `tri` seen at pixel `(x, y)`: the
/// first set's coordinates and their screen derivatives (by central differences over 1/16
/// pixel on the triangle's plane: the renderer's, exact at the centre), and the texels.
fn texels_at(
    scene: &Scene,
    obj: &Object,
    tri: [u32; 3],
    bary: [f64; 3],
    (x, y): (u32, u32),
) -> (Vec2, Vec2, Vec2, Texels) {
    let mesh = &obj.mesh;
    let ps = tri.map(|i| mesh.positions()[i as usize]);
    // Set `k`'s coordinates at barycentrics `b`.
    let uv_at = |k: usize, b: [f64; 3]| {
        let set = if k == 0 { mesh.uvs() } else { mesh.uvs1() };
        let uvs = tri.map(|i| set.get(i as usize).copied().unwrap_or_default().as_dvec2());
        uvs[0] * b[0] + uvs[1] * b[1] + uvs[2] * b[2]
    };
    let corners = ps.map(|p| p.as_dvec3());
    let (fx, fy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
    // Each set's coordinates and their derivatives as the renderer's (exact at the centre),
    // by central differences over 1/16 pixel on the triangle's plane.
    let h = 1.0 / 16.0;
    let set = |k: usize| {
        let at = |dx: f64, dy: f64| plane_barycentrics(ray(scene, fx + dx, fy + dy), corners).map(|b| uv_at(k, b));
        let derivative = |dx: f64, dy: f64| match (at(dx * h, dy * h), at(-dx * h, -dy * h)) {
            (Some(a), Some(b)) => ((a - b) / (2.0 * h)).as_vec2(),
            _ => Vec2::ZERO,
        };
        [uv_at(k, bary).as_vec2(), derivative(1.0, 0.0), derivative(0.0, 1.0)]
    };
    let first = set(0);
    let second = if obj.maps.uses_second_set() { set(1) } else { first };
    let [uv, d_dx, d_dy] = first;
    let mut texels = obj.maps.sample_sets(&[first, second]);
    if !mesh.colors().is_empty() {
        let c = tri.map(|i| mesh.colors()[i as usize]);
        let w = bary.map(|w| w as f32);
        texels = texels.tinted(c[0] * w[0] + c[1] * w[1] + c[2] * w[2]);
    }
    (uv, d_dx, d_dy, texels)
}

/// What the probe says of a textured point: its coordinates and texels, and (in `notes`) the
/// diffuse texel, the alpha and whether the alpha test discards it.
fn texture_value(obj: &Object, [uv, d_dx, d_dy]: [Vec2; 3], t: &Texels, notes: &mut Vec<String>) -> TextureValue {
    let alpha = Maps::alpha(&obj.material, t);
    let discarded = obj.maps.discards(alpha);
    notes.push(format!(
        "textured: uv ({:.4}, {:.4}); diffuse texel ({:.3}, {:.3}, {:.3}), alpha {alpha:.3}{}",
        uv.x,
        uv.y,
        t.diffuse[0],
        t.diffuse[1],
        t.diffuse[2],
        if discarded {
            ": discarded by the alpha test (the renderer shows what is behind)"
        } else {
            ""
        }
    ));
    TextureValue {
        uv: uv.to_array(),
        uv_dx: d_dx.to_array(),
        uv_dy: d_dy.to_array(),
        diffuse: t.diffuse,
        specular: c3(t.specular),
        shininess: t.shininess,
        occlusion: t.occlusion.unwrap_or(1.0),
        alpha,
        discarded,
    }
}

/// The per-light numbers at `position` with `normal`, and `at`'s totals.
fn hit_terms(scene: &Scene, obj: &Object, view: &View, position: Vec3, normal: Vec3, at: &Shading) -> Hit {
    let m = &obj.material;
    let opts = obj.shading.options;
    let s = m.shininess();
    let n = normal.normalize_or_zero();
    let v = view.at(position);
    let (kd, ks) = opts.normalization.factors(s);
    // The material without emission, for per-light terms; lights alone, no global ambient.
    let bare = Material::new(m.ambient(), m.diffuse(), m.specular(), Color::BLACK, s).unwrap_or(*m);
    let alone = ShadingOptions {
        clamp: false,
        two_sided: false,
        ..opts
    };
    let lights = scene
        .lighting
        .lights()
        .iter()
        .map(|light| {
            let inc = light.incidence(position);
            let l = inc.to_light;
            let r = 2.0 * l.dot(n) * n - l;
            let h = (l + v).normalize_or_zero();
            let distance = light.position().map(|p| (p - position).length());
            let attenuation = match (light.attenuation(), distance) {
                (Some(a), Some(d)) => a.factor(d),
                _ => 1.0,
            };
            let spot = if attenuation > 0.0 {
                inc.factor / attenuation
            } else {
                0.0
            };
            let lighting = Lighting::new(Color::BLACK, vec![*light]).expect("a valid light");
            let one = shade(&SurfacePoint { position, normal: n }, view, &bare, &lighting, &alone);
            let lc = light.color();
            LightTerms {
                kind: match light {
                    Light::Directional(_) => "directional",
                    Light::Point(_) => "point",
                    Light::Spot(_) => "spot",
                },
                l: v3(l),
                r: v3(r),
                h: v3(h),
                n_dot_l: n.dot(l),
                r_dot_v: r.dot(v),
                n_dot_h: n.dot(h),
                distance,
                attenuation,
                spot,
                spec: if l == Vec3::ZERO || n == Vec3::ZERO || v == Vec3::ZERO {
                    0.0
                } else {
                    specular_factor(opts.specular, n, l, v, s)
                },
                lit: n.dot(l) > 0.0 || !opts.gate_specular,
                ambient: c3(one.ambient),
                diffuse: c3(one.diffuse),
                specular: c3(one.specular),
                colors: [c3(lc.ambient()), c3(lc.diffuse()), c3(lc.specular())],
            }
        })
        .collect();
    let sum = at.ambient + at.diffuse + at.specular;
    Hit {
        object: 0,
        name: String::new(),
        triangle: 0,
        barycentric: [0.0; 3],
        back_face: false,
        interpolation: "phong",
        output: "color",
        position: v3(position),
        normal: v3(n),
        view: v3(v),
        material: MaterialNumbers {
            ambient: c3(m.ambient()),
            diffuse: c3(m.diffuse()),
            specular: c3(m.specular()),
            emission: c3(m.emission()),
            shininess: s,
        },
        normalization: [kd, ks],
        gate_specular: opts.gate_specular,
        clamp: opts.clamp,
        specular_model: match opts.specular {
            SpecularModel::None => "none",
            SpecularModel::Phong => "phong",
            SpecularModel::BlinnPhong => "blinn-phong",
            SpecularModel::Lyon { .. } => "lyon",
        },
        global_ambient: c3(m.emission() + m.ambient() * scene.lighting.ambient()),
        ambient_light: c3(scene.lighting.ambient()),
        lights,
        ambient: c3(at.ambient),
        diffuse: c3(at.diffuse),
        specular: c3(at.specular),
        sum: c3(sum),
        color: c3(at.color),
        vertices: Vec::new(),
        texture: None,
    }
}
