//! A glTF file's textures: the ones each material uses that phong renders (their slots,
//! coordinate sets and KHR_texture_transform), their images (the core `source`, else
//! EXT_texture_webp's) and samplers, read into a primitive's maps.

use super::buffers::{Buffer, floats, percent_decode};
use crate::texture_file::{MapRequest, Slot, Source, TextureCache, resolve};
use base64::Engine;
use glam::{Mat2, Vec2};
use phong_core::{Channel, Color, Filter, Maps, Material, MipFilter, Sampler, UvTransform, Wrap};
use std::path::Path;

/// The file's textures as they are read: where from, the images decoded so far, and the white
/// emission map (one for the file, uploaded once by the GPU).
pub(super) struct Textures<'a> {
    pub(super) path: &'a Path,
    pub(super) doc: &'a ::gltf::Document,
    pub(super) resource: &'a dyn Fn(&str) -> Result<Vec<u8>, String>,
    pub(super) cache: TextureCache,
    pub(super) white: Option<std::sync::Arc<phong_core::Texture>>,
}

impl Textures<'_> {
    /// A primitive's maps and its two sets of texture coordinates (`v` flipped to OpenGL's),
    /// for its `n` vertices; `material` becomes the one a metallic-roughness map scales.
    pub(super) fn maps(
        &mut self,
        prim: &::gltf::Primitive,
        n: usize,
        buffers: &[Buffer],
        what: &str,
        material: &mut Option<Material>,
        warnings: &mut Vec<String>,
    ) -> (Maps, Vec<Vec2>, Vec<Vec2>) {
        let path = self.path;
        let mat = &prim.material();
        // The mesh's first set is the normal texture's (its tangents are made from it), else
        // the base colour's (else the first used); its second, the other of TEXCOORD_0 and
        // TEXCOORD_1 used, if any. A third set is not read.
        let mut infos = texture_infos(mat);
        let first = infos
            .iter()
            .find(|t| t.slot == Slot::Normal)
            .or(infos.first())
            .map(|t| t.set);
        let second = infos.iter().map(|t| t.set).find(|&s| Some(s) != first && s <= 1);
        let read_set = |set: Option<u32>| -> Vec<Vec2> {
            match set.and_then(|s| floats::<2>(&prim.get(&::gltf::Semantic::TexCoords(s))?, buffers)) {
                Some(t) => {
                    let uv: Vec<Vec2> = t.into_iter().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect();
                    if uv.len() == n && uv.iter().all(|u| u.is_finite()) {
                        uv
                    } else {
                        Vec::new()
                    }
                }
                None => Vec::new(),
            }
        };
        let (uvs, uvs1) = (read_set(first), read_set(second));
        let beyond = infos
            .iter()
            .filter(|t| Some(t.set) != first && Some(t.set) != second)
            .count();
        if beyond > 0 {
            warnings.push(format!(
                "{}: {what}: {beyond} textures not used: they read a third texture coordinate set (phong reads two)",
                path.display()
            ));
        }
        if second.is_some() && uvs1.is_empty() && !uvs.is_empty() {
            warnings.push(format!(
                "{}: {what}: textures on TEXCOORD_{} not used: the primitive has no usable TEXCOORD_{0}",
                path.display(),
                second.unwrap_or(1)
            ));
        }
        // Each texture's set as the mesh's: 0 the first, 1 the second.
        infos.retain(|t| Some(t.set) == first || (Some(t.set) == second && !uvs1.is_empty()));
        for t in &mut infos {
            t.set = u32::from(Some(t.set) != first);
        }
        let maps = if mat.index().is_some() && !uvs.is_empty() {
            // Once a texture (an unlit material's may fill two slots).
            let mut imageless: Vec<usize> = Vec::new();
            for t in infos.iter().filter(|t| texture_image(&t.texture, self.doc).is_none()) {
                if imageless.contains(&t.texture.index()) {
                    continue;
                }
                imageless.push(t.texture.index());
                warnings.push(format!(
                    "{}: {what}: texture {} has no image phong reads (no source, nor EXT_texture_webp's): not used",
                    path.display(),
                    t.texture.index()
                ));
            }
            let requests: Vec<MapRequest> = infos
                .iter()
                .filter_map(|t| texture_request(t, self.doc, buffers, what))
                .collect();
            let mut maps = resolve(
                &requests,
                mat.name().unwrap_or("(unnamed)"),
                self.resource,
                &mut self.cache,
                warnings,
            );
            // The alpha test where the material asks for it (an alpha map alone would
            // bring one).
            maps.alpha_cutoff =
                (mat.alpha_mode() == ::gltf::material::AlphaMode::Mask).then(|| mat.alpha_cutoff().unwrap_or(0.5));
            // The factors go with the map, and the material becomes the one it scales.
            if let (Some(mr), Some(m)) = (&mut maps.metal_rough, &mut *material) {
                let pbr = mat.pbr_metallic_roughness();
                let b = pbr.base_color_factor();
                mr.base_factor = Color::new(b[0], b[1], b[2]).clamp01();
                mr.metallic = pbr.metallic_factor().clamp(0.0, 1.0);
                mr.roughness = pbr.roughness_factor().clamp(0.0, 1.0);
                *m = mr.material(m.emission(), m.alpha());
            }
            // glTF's emission is not the base colour's to modulate (GL_MODULATE's would be):
            // a white emission map keeps it apart.
            let modulated = maps.diffuse.is_some() || maps.metal_rough.is_some();
            if maps.emission.is_none() && modulated && material.is_some_and(|m| m.emission() != Color::BLACK) {
                let white = self.white.get_or_insert_with(|| {
                    std::sync::Arc::new(phong_core::Texture::from_rgba8(1, 1, &[[255; 4]]).expect("a 1×1 texture"))
                });
                maps.emission = Some(phong_core::TextureMap::new(std::sync::Arc::clone(white)));
            }
            maps
        } else {
            if !infos.is_empty() {
                warnings.push(format!(
                    "{}: {what}: textures not used: the primitive has no usable TEXCOORD_{}",
                    path.display(),
                    first.unwrap_or(0)
                ));
            }
            Maps::default()
        };
        // `alphaMode: BLEND`: blended by the base colour's alpha (and its texture's).
        let maps = Maps {
            blend: mat.alpha_mode() == ::gltf::material::AlphaMode::Blend,
            ..maps
        };
        (maps, uvs, uvs1)
    }
}

/// A texture a material uses: its slot, the texture, its coordinate set, its
/// KHR_texture_transform and (a normal texture) its scale.
pub(super) struct Tex<'a> {
    slot: Slot,
    texture: ::gltf::Texture<'a>,
    pub(super) set: u32,
    transform: Option<::gltf::texture::TextureTransform<'a>>,
    scale: f32,
}

impl<'a> Tex<'a> {
    fn of(slot: Slot, info: ::gltf::texture::Info<'a>) -> Tex<'a> {
        let transform = info.texture_transform();
        Tex {
            slot,
            texture: info.texture(),
            // KHR_texture_transform's own `texCoord` overrides the texture info's.
            set: transform
                .as_ref()
                .and_then(|t| t.tex_coord())
                .unwrap_or(info.tex_coord()),
            transform,
            scale: 1.0,
        }
    }
}

/// The textures a material uses that phong renders, with their slots: base colour (or
/// KHR_materials_pbrSpecularGlossiness's diffuse texture), emission, metallic-roughness,
/// occlusion, normal.
pub(super) fn texture_infos<'a>(mat: &::gltf::Material<'a>) -> Vec<Tex<'a>> {
    let mut out = Vec::new();
    if mat.unlit() {
        // KHR_materials_unlit: the base colour texture alone, as the emission map (the
        // material is all emission) and, where the material is cut out or blended, as the
        // alpha map; the other textures do not apply.
        let Some(base) = mat.pbr_metallic_roughness().base_color_texture() else {
            return out;
        };
        if mat.alpha_mode() != ::gltf::material::AlphaMode::Opaque {
            out.push(Tex::of(Slot::Alpha, base.clone()));
        }
        out.insert(0, Tex::of(Slot::Emission, base));
        return out;
    }
    let diffuse = match mat.pbr_specular_glossiness() {
        Some(sg) => sg.diffuse_texture(),
        None => mat.pbr_metallic_roughness().base_color_texture(),
    };
    if let Some(t) = diffuse {
        out.push(Tex::of(Slot::Diffuse, t));
    }
    if let Some(t) = mat.emissive_texture() {
        out.push(Tex::of(Slot::Emission, t));
    }
    if mat.pbr_specular_glossiness().is_none()
        && let Some(t) = mat.pbr_metallic_roughness().metallic_roughness_texture()
    {
        out.push(Tex::of(Slot::MetalRough, t));
    }
    if let Some(o) = mat.occlusion_texture() {
        out.push(Tex {
            slot: Slot::Occlusion,
            texture: o.texture(),
            set: o.tex_coord(),
            transform: None,
            scale: o.strength(),
        });
    }
    if let Some(n) = mat.normal_texture() {
        let t = Tex {
            slot: Slot::Normal,
            texture: n.texture(),
            set: n.tex_coord(),
            transform: None,
            scale: n.scale(),
        };
        out.push(t);
    }
    out
}

/// A texture's image: its own `source`, else EXT_texture_webp's (a WebP image without a
/// fallback; where a file gives both, the fallback is read, as before the extension was).
fn texture_image<'d>(texture: &::gltf::Texture<'d>, doc: &'d ::gltf::Document) -> Option<::gltf::Image<'d>> {
    texture.source().or_else(|| {
        let i = texture.extension_value("EXT_texture_webp")?.get("source")?.as_u64()?;
        doc.images().nth(usize::try_from(i).ok()?)
    })
}

/// A glTF texture as a map request: its image (a buffer view's bytes, a data URI, or a file
/// read by the loader's reader), sampler and KHR_texture_transform, in OpenGL's coordinates.
fn texture_request(tex: &Tex, doc: &::gltf::Document, buffers: &[Buffer], what: &str) -> Option<MapRequest> {
    let (slot, texture) = (tex.slot, tex.texture.clone());
    let image = texture_image(&texture, doc)?;
    let name = format!("image {}", image.index());
    let source = match image.source() {
        ::gltf::image::Source::View { view, .. } => {
            let data = buffers.get(view.buffer().index())?;
            let end = view.offset().checked_add(view.length())?;
            Source::Bytes(std::sync::Arc::new(data.get(view.offset()..end)?.to_vec()), name)
        }
        ::gltf::image::Source::Uri { uri, .. } => match uri.strip_prefix("data:") {
            Some(rest) => {
                let (_, data) = rest.split_once(";base64,")?;
                let bytes = base64::engine::general_purpose::STANDARD.decode(data).ok()?;
                Source::Bytes(std::sync::Arc::new(bytes), name)
            }
            None => Source::File(percent_decode(uri)),
        },
    };
    let s = texture.sampler();
    let wrap = |w: ::gltf::texture::WrappingMode| match w {
        ::gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
        ::gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
        ::gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
    };
    use ::gltf::texture::{MagFilter, MinFilter};
    let (min, mip) = match s.min_filter() {
        Some(MinFilter::Nearest) => (Filter::Nearest, MipFilter::None),
        Some(MinFilter::Linear) => (Filter::Linear, MipFilter::None),
        Some(MinFilter::NearestMipmapNearest) => (Filter::Nearest, MipFilter::Nearest),
        Some(MinFilter::LinearMipmapNearest) => (Filter::Linear, MipFilter::Nearest),
        Some(MinFilter::NearestMipmapLinear) => (Filter::Nearest, MipFilter::Linear),
        Some(MinFilter::LinearMipmapLinear) | None => (Filter::Linear, MipFilter::Linear),
    };
    let sampler = Sampler {
        wrap_u: wrap(s.wrap_s()),
        wrap_v: wrap(s.wrap_t()),
        mag: if s.mag_filter() == Some(MagFilter::Nearest) {
            Filter::Nearest
        } else {
            Filter::Linear
        },
        min,
        mip,
    };
    // glTF's transform acts on its coordinates (v down); ours are flipped: F·M·F.
    let flip = UvTransform {
        linear: Mat2::from_diagonal(Vec2::new(1.0, -1.0)),
        offset: Vec2::new(0.0, 1.0),
    };
    let m = match &tex.transform {
        Some(t) => {
            let (sin, cos) = t.rotation().sin_cos();
            let rotation = Mat2::from_cols(Vec2::new(cos, -sin), Vec2::new(sin, cos));
            UvTransform {
                linear: rotation * Mat2::from_diagonal(Vec2::from(t.scale())),
                offset: Vec2::from(t.offset()),
            }
        }
        None => UvTransform::default(),
    };
    Some(MapRequest {
        slot,
        source,
        transform: flip.after(&m.after(&flip)),
        sampler,
        // (An unlit material's alpha map: its base colour texture's alpha.)
        channel: (slot == Slot::Alpha).then_some(Channel::A),
        srgb: true,
        at: what.to_string(),
        scale: tex.scale,
        green_down: false,
        set: u8::from(tex.set == 1),
    })
}
