//! An object's texture maps on the GPU (the render pipeline's group 1): each texture with the
//! CPU's mipmap chain (level by level, so the mipmaps are the CPU's), a sampler per map with
//! its wrap and filters, and the maps' transforms and flags ([`GpuMaps`]). An untextured object
//! binds a white 1×1 texture and flags that say so.
//!
//! 8-bit textures are `Rgba8Unorm` (the same values as the CPU's); 16-bit ones (16-bit files,
//! sRGB-decoded maps) `Rgba16Float`, filterable on every adapter.

use crate::{Gpu, GpuMaps};
use phong_core::{Channel, Filter, Maps, MipFilter, Texture, TextureMap, Wrap};
use std::sync::Arc;

/// The maps' order in [`GpuMaps`] and the group's bindings (textures at 1.., samplers at 10..).
const SLOTS: usize = 9;

/// The layout of group 1: the uniform [`GpuMaps`], nine textures, nine samplers.
pub(crate) fn maps_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: both,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }];
    for k in 0..SLOTS as u32 {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 1 + k,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        });
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 1 + SLOTS as u32 + k,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("phong maps"),
        entries: &entries,
    })
}

fn channel(c: Channel) -> u32 {
    match c {
        Channel::R => 0,
        Channel::G => 1,
        Channel::B => 2,
        Channel::A => 3,
        Channel::Luminance => 4,
    }
}

fn address(w: Wrap) -> wgpu::AddressMode {
    match w {
        Wrap::Repeat => wgpu::AddressMode::Repeat,
        Wrap::Clamp => wgpu::AddressMode::ClampToEdge,
        Wrap::Mirror => wgpu::AddressMode::MirrorRepeat,
    }
}

fn filter(f: Filter) -> wgpu::FilterMode {
    match f {
        Filter::Nearest => wgpu::FilterMode::Nearest,
        Filter::Linear => wgpu::FilterMode::Linear,
    }
}

impl Gpu {
    /// A texture with `t`'s levels.
    fn upload_texture(&self, t: &Texture) -> wgpu::TextureView {
        let eight = t.bits() == 8;
        let format = if eight {
            wgpu::TextureFormat::Rgba8Unorm
        } else {
            wgpu::TextureFormat::Rgba16Float
        };
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("phong map"),
            size: wgpu::Extent3d {
                width: t.width(),
                height: t.height(),
                depth_or_array_layers: 1,
            },
            mip_level_count: t.level_count() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for level in 0..t.level_count() {
            // Rows bottom first, as the CPU keeps them: v = 0 is row 0 on both.
            let (w, h, bytes): (u32, u32, Vec<u8>) = match (t.level8(level), t.level16(level)) {
                (Some((w, h, texels)), _) => (w, h, texels.as_flattened().to_vec()),
                (None, Some((w, h, texels))) => (
                    w,
                    h,
                    texels
                        .iter()
                        .flat_map(|p| p.map(|c| half::f16::from_f32(f32::from(c) / 65535.0)))
                        .flat_map(|h| h.to_le_bytes())
                        .collect(),
                ),
                (None, None) => continue,
            };
            self.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: level as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                &bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(w * if eight { 4 } else { 8 }),
                    rows_per_image: Some(h),
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
        }
        texture.create_view(&Default::default())
    }

    /// A sampler for `m`: its wrap and filters; without mipmap filtering, level 0 only.
    fn sampler(&self, m: &TextureMap) -> wgpu::Sampler {
        let s = &m.sampler;
        self.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("phong map"),
            address_mode_u: address(s.wrap_u),
            address_mode_v: address(s.wrap_v),
            mag_filter: filter(s.mag),
            min_filter: filter(s.min),
            mipmap_filter: match s.mip {
                MipFilter::Linear => wgpu::MipmapFilterMode::Linear,
                _ => wgpu::MipmapFilterMode::Nearest,
            },
            lod_max_clamp: if s.mip == MipFilter::None { 0.0 } else { 32.0 },
            ..Default::default()
        })
    }

    /// Group 1 for each object: `(maps, blends, vertex colours, material alpha)` (maps empty
    /// for untextured objects).
    pub(crate) fn map_bind_groups(&self, objects: &[(Maps, bool, bool, f32)]) -> Vec<wgpu::BindGroup> {
        let white = Texture::new(1, 1, &[[u16::MAX; 4]], 8).expect("a 1×1 texture");
        let white_view = self.upload_texture(&white);
        let plain = self.device.create_sampler(&Default::default());
        let mut cache = self.textures.lock().unwrap_or_else(|e| e.into_inner());
        cache.retain(|(t, _)| t.strong_count() > 0);
        let mut view_of = |t: &Arc<Texture>| -> wgpu::TextureView {
            let found = cache
                .iter()
                .find(|(w, _)| w.upgrade().is_some_and(|u| Arc::ptr_eq(&u, t)));
            if let Some((_, v)) = found {
                return v.clone();
            }
            let v = self.upload_texture(t);
            cache.push((Arc::downgrade(t), v.clone()));
            v
        };
        objects
            .iter()
            .map(|(maps, blends, colors, alpha)| {
                let slots: [Option<&TextureMap>; SLOTS] = [
                    maps.diffuse.as_ref(),
                    maps.ambient.as_ref(),
                    maps.specular.as_ref(),
                    maps.emission.as_ref(),
                    maps.shininess.as_ref().map(|(m, _)| m),
                    maps.alpha.as_ref().map(|(m, _)| m),
                    maps.normal.as_ref().map(|n| &n.map),
                    maps.metal_rough.as_ref().map(|m| &m.map),
                    maps.occlusion.as_ref().map(|o| &o.map),
                ];
                let mut params = GpuMaps {
                    present: std::array::from_fn(|k| u32::from(slots[k].is_some())),
                    scalar: [
                        u32::from(slots[4].is_some()),
                        u32::from(slots[5].is_some()),
                        maps.shininess.as_ref().map_or(0, |(_, c)| channel(*c)),
                        maps.alpha.as_ref().map_or(0, |(_, c)| channel(*c)),
                    ],
                    cutoff: [
                        maps.alpha_cutoff.unwrap_or(0.0),
                        f32::from(u8::from(maps.alpha_cutoff.is_some())),
                        f32::from(u8::from(!maps.is_empty() || *colors)),
                        *alpha,
                    ],
                    blend: [f32::from(u8::from(*blends)), f32::from(u8::from(*colors)), 0.0, 0.0],
                    normal: maps
                        .normal
                        .as_ref()
                        .map_or([0.0; 4], |n| [1.0, n.scale, f32::from(u8::from(n.green_down)), 0.0]),
                    pbr: [
                        f32::from(u8::from(maps.metal_rough.is_some())),
                        maps.metal_rough.as_ref().map_or(0.0, |m| m.metallic),
                        maps.metal_rough.as_ref().map_or(0.0, |m| m.roughness),
                        f32::from(u8::from(maps.occlusion.is_some())),
                    ],
                    base: {
                        let b = maps
                            .metal_rough
                            .as_ref()
                            .map_or(phong_core::Color::WHITE, |m| m.base_factor);
                        [b.r, b.g, b.b, maps.occlusion.as_ref().map_or(1.0, |o| o.strength)]
                    },
                    ..Default::default()
                };
                let mut samplers = Vec::new();
                let mut texture_views = Vec::new();
                for (k, slot) in slots.iter().enumerate() {
                    let Some(m) = slot else {
                        params.transforms[2 * k] = [1.0, 0.0, 0.0, 1.0];
                        texture_views.push(None);
                        samplers.push(None);
                        continue;
                    };
                    let l = m.transform.linear;
                    params.transforms[2 * k] = [l.x_axis.x, l.x_axis.y, l.y_axis.x, l.y_axis.y];
                    let set = f32::from(m.set.min(1));
                    params.transforms[2 * k + 1] = [m.transform.offset.x, m.transform.offset.y, set, 0.0];
                    texture_views.push(Some(view_of(&m.texture)));
                    samplers.push(Some(self.sampler(m)));
                }
                let uniform = self.buffer_init("maps", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
                let mut entries = vec![wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                }];
                for k in 0..SLOTS {
                    let view = texture_views[k].as_ref().unwrap_or(&white_view);
                    entries.push(wgpu::BindGroupEntry {
                        binding: 1 + k as u32,
                        resource: wgpu::BindingResource::TextureView(view),
                    });
                    entries.push(wgpu::BindGroupEntry {
                        binding: 1 + (SLOTS + k) as u32,
                        resource: wgpu::BindingResource::Sampler(samplers[k].as_ref().unwrap_or(&plain)),
                    });
                }
                self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("phong maps"),
                    layout: &self.maps_layout,
                    entries: &entries,
                })
            })
            .collect()
    }
}
