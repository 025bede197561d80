//! glTF 2.0 models (`.gltf` with `.bin` files or data URIs, `.glb`), with the `gltf` crate:
//! every triangle primitive of the default scene, placed by its nodes' transforms, with its
//! material turned into a Phong material; the file's first camera and its KHR_lights_punctual
//! lights, for a model alone.
//!
//! The material mapping (metallic-roughness, the glTF default):
//! `diffuse = base·(1 − metallic)`, `specular = mix(0.04, base, metallic)`,
//! `ambient = diffuse`, `emission = emissive·strength`, `alpha = base alpha`, and the
//! shininess from the roughness as Blinn-Phong's equivalent of the Beckmann distribution:
//! `α = roughness²`, `s = 2/α² − 2` (capped at [`MetalRough::MAX_SHININESS`]).
//! KHR_materials_pbrSpecularGlossiness: `diffuse`, `specular` as given, `roughness = 1 −
//! glossiness`. KHR_materials_unlit: the base colour as emission, nothing lit. A primitive
//! without a material gets OpenGL's default material (as an OBJ
//! without MTL), not glTF's metallic default, which would be a black mirror here.
//!
//! Textures: the base colour texture (sRGB) is the diffuse map (modulating the diffuse and
//! ambient colours as the factor does; its alpha multiplies the material's), the emissive
//! texture (sRGB) the emission map, with their texture coordinate sets, KHR_texture_transform
//! and samplers; the normal texture (with its scale) the normal map; the metallic-roughness
//! texture the same mapping per texel (phong-core's `MetalRough`); the occlusion texture (with
//! its strength) scales the ambient terms. `alphaMode: MASK` is the alpha test at `alphaCutoff`. Texture coordinates are
//! flipped to OpenGL's (`v = 1 − v`: glTF's `v` runs down the image).

mod buffers;
mod textures;

use super::ModelPart;
use super::far_origin;
use crate::Error;
use crate::texture_file::TextureCache;
use buffers::{Buffer, Components, check_accessor, floats, floats_as, load_buffers, packed_indices};
use glam::{DMat3, DMat4, DVec3, Vec2, Vec3, Vec4};
use phong_core::{Color, Maps, Material, Mesh, MetalRough};
use std::collections::BTreeSet;
use std::path::Path;
use textures::{Textures, texture_infos};

/// Extensions phong reads; any other required extension is refused.
const SUPPORTED: [&str; 7] = [
    "KHR_mesh_quantization",
    "EXT_texture_webp",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
    "KHR_materials_unlit",
];

/// A camera of the file, in its coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FileCamera {
    /// Eye.
    pub position: DVec3,
    /// The direction it looks (the node's −z).
    pub forward: DVec3,
    /// Its up (the node's +y).
    pub up: DVec3,
    /// Vertical field of view, degrees (`None`: orthographic).
    pub fov_deg: Option<f32>,
}

/// A light of the file (KHR_lights_punctual), in its coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct FileLight {
    /// `"directional"`, `"point"` or `"spot"`.
    pub kind: &'static str,
    /// Position (point, spot).
    pub position: DVec3,
    /// Direction the light travels (directional, spot).
    pub direction: DVec3,
    /// Colour times intensity.
    pub color: [f32; 3],
    /// Spot: the outer cone's half-angle, degrees.
    pub cutoff_deg: f32,
}

/// A glTF model: its parts, and the file's first camera and its lights.
#[derive(Clone, Debug, Default)]
pub struct GltfModel {
    /// One part per primitive (positions in world space, re-centred together).
    pub parts: Vec<ModelPart>,
    /// The first camera met in the default scene.
    pub camera: Option<FileCamera>,
    /// The KHR_lights_punctual lights of the default scene.
    pub lights: Vec<FileLight>,
    /// Whether any primitive's material is double-sided (glTF culls back faces otherwise).
    pub double_sided: bool,
}

/// Reads a glTF model from `bytes` (a `.gltf` JSON or a `.glb`), its external buffers read
/// by `resource` (given the URI, percent-decoded, relative to the model's folder).
pub fn read_gltf(
    path: &Path,
    bytes: &[u8],
    resource: &dyn Fn(&str) -> Result<Vec<u8>, String>,
    warnings: &mut Vec<String>,
) -> Result<GltfModel, Error> {
    let fail = |m: String| Error::Model {
        path: path.to_path_buf(),
        message: format!("glTF: {m}"),
    };
    // One parse of the JSON, checked, then validated; a GLB's binary chunk borrowed, not copied.
    let gltf_err = |e: ::gltf::Error| fail(e.to_string());
    let (json, bin) = if bytes.starts_with(b"glTF") {
        let glb = ::gltf::Glb::from_slice(bytes).map_err(gltf_err)?;
        (glb.json, glb.bin)
    } else {
        (std::borrow::Cow::Borrowed(bytes), None)
    };
    let mut root: ::gltf::json::Root =
        ::gltf::json::deserialize::from_slice(&json).map_err(|e| gltf_err(::gltf::Error::Deserialize(e)))?;
    check_before_validation(&root, &fail)?;
    // Every required extension is one phong reads (checked above); the crate's validation
    // would refuse those it does not parse itself (KHR_mesh_quantization).
    root.extensions_required.clear();
    let document = ::gltf::Document::from_json(root).map_err(gltf_err)?;
    let doc = &document;
    let buffers = load_buffers(doc, bin, resource, &fail)?;
    let instances = node_instances(doc, &fail)?;
    let mut model = GltfModel::default();
    let (mut skipped_modes, mut colours) = (0usize, 0usize);
    let mut textures = Textures {
        path,
        doc,
        resource,
        cache: TextureCache::default(),
        white: None,
    };
    // Positions in f64 world space for all parts, re-centred together below.
    let mut pending: Vec<Pending> = Vec::new();
    let mut triangles_total: u64 = 0;
    for (node, world) in &instances {
        if model.camera.is_none() {
            model.camera = file_camera(node, world);
        }
        model.lights.extend(file_light(node, world));
        let Some(mesh) = node.mesh() else { continue };
        for prim in mesh.primitives() {
            if !matches!(
                prim.mode(),
                ::gltf::mesh::Mode::Triangles | ::gltf::mesh::Mode::TriangleStrip | ::gltf::mesh::Mode::TriangleFan
            ) {
                skipped_modes += 1;
                continue;
            }
            let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
            let has_normal_accessor = check_primitive(&prim, &buffers, &what, &fail)?;
            let g = geometry(&prim, &buffers, world, has_normal_accessor, &what, &fail)?;
            colours += usize::from(g.colours_dropped);
            triangles_total += g.tris.len() as u64;
            if triangles_total > phong_core::limits::MAX_SCENE_TRIANGLES {
                return Err(fail(format!(
                    "more than {} triangles (MAX_SCENE_TRIANGLES)",
                    phong_core::limits::MAX_SCENE_TRIANGLES
                )));
            }
            let mat = prim.material();
            model.double_sided |= mat.double_sided();
            let mut material = mat.index().map(|_| phong_material(&mat));
            let (maps, uvs, uvs1) = textures.maps(&prim, g.world_pos.len(), &buffers, &what, &mut material, warnings);
            let name = format!(
                "{}:{}",
                path.file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                mesh.name()
                    .map_or_else(|| format!("mesh{}", mesh.index()), str::to_string)
            );
            // The file's tangents serve a normal map; without one they are not kept.
            let tangents = if maps.normal.is_some() { g.tangents } else { Vec::new() };
            // Vertex colours tint the diffuse term, which an unlit material has none of.
            let colors = if mat.unlit() && !g.colors.is_empty() {
                warnings.push(format!(
                    "{}: {what}: vertex colours (COLOR_0) not used: its material is unlit (KHR_materials_unlit)",
                    path.display()
                ));
                Vec::new()
            } else {
                g.colors
            };
            pending.push(Pending {
                name,
                tangents,
                world_pos: g.world_pos,
                normals: g.normals,
                tris: g.tris,
                material,
                has_normals: g.has_normals,
                uvs,
                uvs1,
                colors,
                maps,
            });
        }
    }
    if pending.is_empty() {
        return Err(fail(format!(
            "no triangles in the default scene: nothing to render{}",
            if skipped_modes > 0 {
                format!(" ({skipped_modes} primitives of points or lines skipped)")
            } else {
                String::new()
            }
        )));
    }
    let file = path.display();
    if skipped_modes > 0 {
        warnings.push(format!(
            "{file}: {skipped_modes} primitives of points or lines skipped: phong draws surfaces"
        ));
    }
    if colours > 0 {
        warnings.push(format!(
            "{file}: vertex colours (COLOR_0, {colours} primitives) are not used: not one finite colour per vertex"
        ));
    }
    model.parts = into_parts(pending, &fail)?;
    Ok(model)
}

/// What the `gltf` crate's own validation would not say, or would panic on: a required
/// extension phong does not read (the crate refuses it without saying why), and a primitive's
/// accessor index out of range (gltf-json's validation indexes the POSITION accessor
/// unchecked: found by the `gltf` fuzz target).
fn check_before_validation(json: &::gltf::json::Root, fail: &dyn Fn(String) -> Error) -> Result<(), Error> {
    for ext in json.extensions_required.iter().map(String::as_str) {
        if !SUPPORTED.contains(&ext) {
            return Err(fail(format!(
                "the file requires the extension {ext}, which phong does not read{}",
                if ext.contains("draco") || ext.contains("meshopt") {
                    " (compressed geometry: decompress it first, e.g. with gltf-transform)"
                } else {
                    ""
                }
            )));
        }
    }
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let refs = prim.attributes.values().chain(prim.indices.as_ref());
            if let Some(bad) = refs.map(|i| i.value()).find(|&i| i >= json.accessors.len()) {
                return Err(fail(format!(
                    "mesh {m} primitive {p} names accessor {bad}, but the file has {}",
                    json.accessors.len()
                )));
            }
        }
    }
    Ok(())
}

/// The camera of `node` placed by `world`, if it has one.
fn file_camera(node: &::gltf::Node, world: &DMat4) -> Option<FileCamera> {
    let cam = node.camera()?;
    let fov_deg = match cam.projection() {
        ::gltf::camera::Projection::Perspective(p) => Some(p.yfov().to_degrees()),
        ::gltf::camera::Projection::Orthographic(_) => None,
    };
    Some(FileCamera {
        position: world.transform_point3(DVec3::ZERO),
        forward: world.transform_vector3(DVec3::NEG_Z).normalize_or(DVec3::NEG_Z),
        up: world.transform_vector3(DVec3::Y).normalize_or(DVec3::Y),
        fov_deg,
    })
}

/// The KHR_lights_punctual light of `node` placed by `world`, if it has one.
fn file_light(node: &::gltf::Node, world: &DMat4) -> Option<FileLight> {
    let light = node.light()?;
    let (kind, cutoff_deg) = match light.kind() {
        ::gltf::khr_lights_punctual::Kind::Directional => ("directional", 0.0),
        ::gltf::khr_lights_punctual::Kind::Point => ("point", 0.0),
        ::gltf::khr_lights_punctual::Kind::Spot { outer_cone_angle, .. } => {
            ("spot", outer_cone_angle.to_degrees().clamp(0.0, 90.0))
        }
    };
    Some(FileLight {
        kind,
        position: world.transform_point3(DVec3::ZERO),
        direction: world.transform_vector3(DVec3::NEG_Z).normalize_or(DVec3::NEG_Z),
        color: light.color().map(|c| c * light.intensity()),
        cutoff_deg,
    })
}

/// Checks every accessor a primitive's reading will use (counts, types, bounds within the
/// buffers), so that the crate's reader cannot fail or panic on them; whether it has normals.
fn check_primitive(
    prim: &::gltf::Primitive,
    buffers: &[Buffer],
    what: &str,
    fail: &dyn Fn(String) -> Error,
) -> Result<bool, Error> {
    use ::gltf::accessor::{DataType, Dimensions};
    let pos = prim
        .get(&::gltf::Semantic::Positions)
        .ok_or_else(|| fail(format!("{what} has no POSITION")))?;
    check_accessor(&pos, buffers, &[Dimensions::Vec3], Components::Any)
        .map_err(|m| fail(format!("{what}: POSITION (accessor {}): {m}", pos.index())))?;
    let normal = prim.get(&::gltf::Semantic::Normals);
    if let Some(a) = &normal {
        check_accessor(a, buffers, &[Dimensions::Vec3], Components::Unit)
            .map_err(|m| fail(format!("{what}: NORMAL (accessor {}): {m}", a.index())))?;
    }
    if let Some(a) = prim.indices() {
        check_accessor(&a, buffers, &[Dimensions::Scalar], Components::Index)
            .map_err(|m| fail(format!("{what}: indices (accessor {}): {m}", a.index())))?;
        // Unsigned integers only, as the specification says (the crate's reader treats any
        // other component type as unreachable: found by the `gltf` fuzz target).
        if !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32) || a.normalized() {
            return Err(fail(format!(
                "{what}: indices (accessor {}) are not unsigned integers",
                a.index()
            )));
        }
    }
    // The texture coordinate sets the material's textures use (checked like the others).
    let sets: BTreeSet<u32> = texture_infos(&prim.material()).iter().map(|t| t.set).collect();
    for &set in &sets {
        if let Some(a) = prim.get(&::gltf::Semantic::TexCoords(set)) {
            check_accessor(&a, buffers, &[Dimensions::Vec2], Components::Any)
                .map_err(|m| fail(format!("{what}: TEXCOORD_{set} (accessor {}): {m}", a.index())))?;
        }
    }
    if let Some(a) = prim.get(&::gltf::Semantic::Colors(0)) {
        check_accessor(&a, buffers, &[Dimensions::Vec3, Dimensions::Vec4], Components::Colour)
            .map_err(|m| fail(format!("{what}: COLOR_0 (accessor {}): {m}", a.index())))?;
    }
    Ok(normal.is_some())
}

/// A primitive's positions in world space.
enum Placed {
    /// The file's own, its node's transform the identity (most files).
    File(Vec<Vec3>),
    /// Moved by its node's transform, in f64.
    World(Vec<DVec3>),
}

impl Placed {
    /// A node without a transform: what the identity gives in f64, without the f64 (the same
    /// numbers, a zero's sign made + as adding the matrix's translation makes it).
    fn file(positions: Vec<[f32; 3]>) -> Placed {
        let mut p: Vec<Vec3> = bytemuck::cast_vec(positions);
        p.iter_mut().for_each(|p| *p += Vec3::ZERO);
        Placed::File(p)
    }

    fn len(&self) -> usize {
        match self {
            Placed::File(p) => p.len(),
            Placed::World(p) => p.len(),
        }
    }

    fn f64s(&self) -> impl Iterator<Item = DVec3> + '_ {
        let (file, world) = match self {
            Placed::File(p) => (&p[..], &[][..]),
            Placed::World(p) => (&[][..], &p[..]),
        };
        file.iter().map(|p| p.as_dvec3()).chain(world.iter().copied())
    }

    /// The positions less `origin`, in f32.
    fn less(self, origin: DVec3) -> Vec<Vec3> {
        match self {
            Placed::File(p) if origin == DVec3::ZERO => p,
            p => p.f64s().map(|w| (w - origin).as_vec3()).collect(),
        }
    }
}

/// A primitive's geometry in world space.
struct Geometry {
    world_pos: Placed,
    normals: Vec<Vec3>,
    has_normals: bool,
    tris: Vec<[u32; 3]>,
    colors: Vec<Color>,
    /// COLOR_0 was there but not one finite colour a vertex: dropped.
    colours_dropped: bool,
    tangents: Vec<Vec4>,
}

/// Reads a checked primitive's positions, vertex colours, triangles (strips and fans
/// unrolled, wound back where `world` mirrors), normals and tangents, placed by `world`.
fn geometry(
    prim: &::gltf::Primitive,
    buffers: &[Buffer],
    world: &DMat4,
    has_normal_accessor: bool,
    what: &str,
    fail: &dyn Fn(String) -> Error,
) -> Result<Geometry, Error> {
    let normal_matrix = DMat3::from_mat4(*world).inverse().transpose();
    let mirrored = DMat3::from_mat4(*world).determinant() < 0.0;
    let reader = prim.reader(|b| buffers.get(b.index()).map(|b| &b[..]));
    let attribute = |s: ::gltf::Semantic| prim.get(&s);
    let positions = attribute(::gltf::Semantic::Positions)
        .and_then(|a| floats::<3>(&a, buffers))
        .ok_or_else(|| fail(format!("{what}: POSITION cannot be read")))?;
    if let Some(i) = phong_core::mesh::not_finite_at(bytemuck::cast_slice(&positions)) {
        let p = positions[i];
        return Err(fail(format!("{what}: position {i} is not finite: {p:?}")));
    }
    let n = positions.len();
    // COLOR_0 multiplies the base colour (the specification): a tint of the diffuse.
    let colours = attribute(::gltf::Semantic::Colors(0)).map(|a| match a.dimensions() {
        ::gltf::accessor::Dimensions::Vec4 => {
            floats_as::<4>(&a, buffers, true).map(|c| c.into_iter().map(|[r, g, b, _]| [r, g, b]).collect())
        }
        _ => floats_as::<3>(&a, buffers, true),
    });
    let (colors, colours_dropped) = match colours {
        Some(c) => {
            let c: Vec<Color> = c
                .unwrap_or_default()
                .into_iter()
                .map(|[r, g, b]| Color::new(r.max(0.0), g.max(0.0), b.max(0.0)))
                .collect();
            if c.len() == n && c.iter().all(|c| c.is_finite()) {
                (c, false)
            } else {
                (Vec::new(), true)
            }
        }
        None => (Vec::new(), false),
    };
    let mut indices: Vec<u32> = match (packed_indices(prim, buffers), reader.read_indices()) {
        (Some(i), _) => i,
        (None, Some(i)) => i.into_u32().collect(),
        (None, None) => (0..n as u32).collect(),
    };
    if let Some(k) = phong_core::mesh::index_at_least(&indices, n) {
        let bad = indices[k];
        return Err(fail(format!("{what}: index {bad} is out of range ({n} vertices)")));
    }
    let mut tris: Vec<[u32; 3]> = match prim.mode() {
        ::gltf::mesh::Mode::TriangleStrip => (2..indices.len())
            .map(|k| {
                let t = [indices[k - 2], indices[k - 1], indices[k]];
                // Every other triangle of a strip is wound the other way.
                if k % 2 == 1 { [t[1], t[0], t[2]] } else { t }
            })
            .collect(),
        ::gltf::mesh::Mode::TriangleFan => (2..indices.len())
            .map(|k| [indices[0], indices[k - 1], indices[k]])
            .collect(),
        _ => {
            // The indices' own memory where its size allows (most files), else a copy.
            indices.truncate(indices.len() / 3 * 3);
            bytemuck::try_cast_vec(indices)
                .unwrap_or_else(|(_, i)| i.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
        }
    };
    if mirrored {
        tris.iter_mut().for_each(|t| t.swap(1, 2));
    }
    let placed = if *world == DMat4::IDENTITY {
        Placed::file(positions)
    } else {
        Placed::World(
            positions
                .iter()
                .map(|p| world.transform_point3(DVec3::from_array(p.map(f64::from))))
                .collect(),
        )
    };
    let file_normals = attribute(::gltf::Semantic::Normals).filter(|_| has_normal_accessor);
    let (normals, has_normals) = match file_normals.map(|a| floats::<3>(&a, buffers).unwrap_or_default()) {
        Some(ns) => {
            let ns: Vec<Vec3> = ns
                .into_iter()
                .map(|v| {
                    (normal_matrix * DVec3::from_array(v.map(f64::from)))
                        .normalize_or_zero()
                        .as_vec3()
                })
                .collect();
            let ok = ns.len() == n;
            (if ok { ns } else { vec![Vec3::ZERO; n] }, ok)
        }
        None => (vec![Vec3::ZERO; n], false),
    };
    // TANGENT (read with normals, as the format pairs them): a direction in the surface,
    // by the node's matrix itself; a mirror flips the bitangent's sign.
    let tangents: Vec<Vec4> = match prim.get(&::gltf::Semantic::Tangents) {
        Some(a) if has_normals => {
            check_accessor(&a, buffers, &[::gltf::accessor::Dimensions::Vec4], Components::Unit)
                .map_err(|m| fail(format!("{what}: TANGENT (accessor {}): {m}", a.index())))?;
            let linear = DMat3::from_mat4(*world);
            let t: Vec<Vec4> = floats::<4>(&a, buffers)
                .unwrap_or_default()
                .into_iter()
                .map(|[x, y, z, w]| {
                    let d = (linear * DVec3::new(x.into(), y.into(), z.into())).normalize_or_zero();
                    d.as_vec3().extend(if mirrored { -w } else { w })
                })
                .collect();
            if t.len() == n && t.iter().all(|t| t.is_finite()) {
                t
            } else {
                Vec::new()
            }
        }
        _ => Vec::new(),
    };
    Ok(Geometry {
        world_pos: placed,
        normals,
        has_normals,
        tris,
        colors,
        colours_dropped,
        tangents,
    })
}

/// The parts of the read primitives, the whole model re-centred together (one origin for
/// every part).
fn into_parts(pending: Vec<Pending>, fail: &dyn Fn(String) -> Error) -> Result<Vec<ModelPart>, Error> {
    let origin = far_origin(pending.iter().flat_map(|p| p.world_pos.f64s()));
    pending
        .into_iter()
        .map(|p| {
            let positions = p.world_pos.less(origin);
            let mesh = Mesh::new(positions, p.normals, p.tris)
                .and_then(|m| m.with_uvs(p.uvs))
                .and_then(|m| m.with_uvs1(p.uvs1))
                .and_then(|m| m.with_colors(p.colors))
                .and_then(|m| m.with_tangents(p.tangents))
                .map_err(|e| fail(format!("{}: {e}", p.name)))?;
            Ok(ModelPart {
                name: p.name,
                mesh,
                material: p.material,
                maps: p.maps,
                has_normals: p.has_normals,
                flat_without_normals: true,
                origin,
                drawn: None,
                fitted: None,
            })
        })
        .collect()
}

/// The nodes of the default scene (else of the first, else every node that is no node's
/// child, as other viewers do) with their world transforms (composed in f64), depth first. A
/// node reached twice (a cycle, or a node with two parents, which the format forbids) is an
/// error; each node is visited once, so the work is linear in the nodes.
fn node_instances<'a>(
    doc: &'a ::gltf::Document,
    fail: &dyn Fn(String) -> Error,
) -> Result<Vec<(::gltf::Node<'a>, DMat4)>, Error> {
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let roots: Vec<::gltf::Node> = match &scene {
        Some(s) => s.nodes().collect(),
        None => {
            let children: BTreeSet<usize> = doc.nodes().flat_map(|n| n.children().map(|c| c.index())).collect();
            doc.nodes().filter(|n| !children.contains(&n.index())).collect()
        }
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut instances = Vec::new();
    let mut stack: Vec<(::gltf::Node, DMat4)> = roots.into_iter().rev().map(|n| (n, DMat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(fail(format!(
                "node {} is reached twice (a cycle in the node tree, or a node with two parents)",
                node.index()
            )));
        }
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        for c in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((c, world));
        }
        instances.push((node, world));
    }
    Ok(instances)
}

/// A primitive read, in f64 world space, waiting for the model's common origin.
struct Pending {
    name: String,
    tangents: Vec<Vec4>,
    uvs: Vec<Vec2>,
    /// The second set of texture coordinates, where a texture reads it.
    uvs1: Vec<Vec2>,
    colors: Vec<Color>,
    maps: Maps,
    world_pos: Placed,
    normals: Vec<Vec3>,
    tris: Vec<[u32; 3]>,
    material: Option<Material>,
    has_normals: bool,
}

/// The Phong material of a glTF material (the mapping in the module's doc).
fn phong_material(m: &::gltf::Material) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let base = pbr.base_color_factor();
    let clean = |x: f32| if x.is_finite() { x.max(0.0) } else { 0.0 };
    if m.unlit() {
        // KHR_materials_unlit: the base colour as it is, whatever the lights: all emission
        // (its texture the emission map, see `texture_infos`).
        let e = Color::new(clean(base[0]), clean(base[1]), clean(base[2]));
        let built = Material::new(Color::BLACK, Color::BLACK, Color::BLACK, e, 1.0).unwrap_or_default();
        return built.with_alpha(clean(base[3]).min(1.0)).unwrap_or(built);
    }
    let (diffuse, specular, roughness, alpha) = match m.pbr_specular_glossiness() {
        Some(sg) => {
            let d = sg.diffuse_factor();
            (
                [d[0], d[1], d[2]],
                sg.specular_factor(),
                1.0 - sg.glossiness_factor(),
                d[3],
            )
        }
        None => {
            let metal = pbr.metallic_factor().clamp(0.0, 1.0);
            let rgb = [base[0], base[1], base[2]];
            (
                rgb.map(|c| c * (1.0 - metal)),
                rgb.map(|c| 0.04 + (c - 0.04) * metal),
                pbr.roughness_factor(),
                base[3],
            )
        }
    };
    let shininess = MetalRough::shininess(roughness);
    let strength = m.emissive_strength().unwrap_or(1.0);
    let col = |c: [f32; 3]| {
        let c = c.map(clean);
        Color::new(c[0], c[1], c[2])
    };
    let d = col(diffuse);
    let built = Material::new(
        d,
        d,
        col(specular),
        col(m.emissive_factor().map(|e| e * strength)),
        shininess,
    )
    .unwrap_or_default();
    built.with_alpha(alpha.clamp(0.0, 1.0)).unwrap_or(built)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node without a transform keeps the file's floats as the f64 transform gives them,
    /// a zero's sign included, re-centred or not.
    #[test]
    fn identity_placement_is_the_f64_transform() {
        let file = [
            [-0.0f32, 0.0, -0.0],
            [1.5, -2.25e-7, 3.0e30],
            [-0.0, -0.0, -0.0],
            [f32::MIN_POSITIVE / 4.0, -1.0e-38, 7.0],
        ];
        let f64_way = |origin: DVec3| -> Vec<[u32; 3]> {
            file.iter()
                .map(|p| (DMat4::IDENTITY.transform_point3(DVec3::from_array(p.map(f64::from))) - origin).as_vec3())
                .map(|v| v.to_array().map(f32::to_bits))
                .collect()
        };
        let placed = || Placed::file(file.to_vec());
        for origin in [DVec3::ZERO, DVec3::new(1.0e6, -2.0, 0.5)] {
            let ours: Vec<[u32; 3]> = placed()
                .less(origin)
                .iter()
                .map(|v| v.to_array().map(f32::to_bits))
                .collect();
            assert_eq!(ours, f64_way(origin), "origin {origin}");
        }
    }
}
