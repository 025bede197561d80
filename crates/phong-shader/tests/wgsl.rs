//! The WGSL target: every module naga validates, and scenes drawn with the modules through
//! wgpu (lavapipe where there is no GPU) match `phong render` at one sample: at most 0.5% of
//! the pixels past 2/255 (triangle edges, where each rasteriser applies its own rule). Without
//! an adapter the render check is skipped, and fails under PHONG_REQUIRE_GPU=1.

mod common;
use common::scenes;
use phong_core::{Interpolation, Scene};
use wgpu::util::DeviceExt;

#[test]
fn every_module_validates() {
    for (what, scene) in scenes() {
        let src = phong_shader::wgsl(&scene, None).unwrap_or_else(|e| panic!("{what}: {e}"));
        let module =
            naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{what}:\n{}", e.emit_to_string(&src)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{what}: {e:?}"));
    }
}

/// wgpu's device, or `None` (the test is skipped) where there is no adapter.
fn device() -> Option<(wgpu::Device, wgpu::Queue)> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default())).ok();
    let Some(adapter) = adapter else {
        if std::env::var("PHONG_REQUIRE_GPU").is_ok_and(|v| v == "1") {
            panic!("PHONG_REQUIRE_GPU=1 but wgpu finds no adapter (apt-get install mesa-vulkan-drivers)");
        }
        eprintln!("skipped: no wgpu adapter");
        return None;
    };
    pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default())).ok()
}

/// `scene` drawn with its WGSL modules: RGBA bytes, rows from the top.
fn draw(device: &wgpu::Device, queue: &wgpu::Queue, scene: &Scene) -> Vec<u8> {
    let (w, h) = (scene.image.width, scene.image.height);
    let target = |format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let color = target(
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let depth = target(
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let bg = scene.image.background;
    let enc = |c: f32| f64::from(scene.image.encoding.encode(c)) / 255.0;
    let mut encoder = device.create_command_encoder(&Default::default());
    // Per object: its pipeline, bind group and buffers (made before the pass borrows them).
    let mut draws = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let src = phong_shader::wgsl(scene, Some(i)).expect("the module");
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: None,
            source: wgpu::ShaderSource::Wgsl(src.into()),
        });
        let flat = o.shading.interpolation == Interpolation::Flat;
        let arrays = phong_shader::vertex_arrays(o);
        let (pos, nor, idx) = (arrays.positions, arrays.normals, arrays.indices);
        let cen = if flat {
            arrays.centroids
        } else {
            vec![glam::Vec3::ZERO; pos.len()]
        };
        let buffer = |bytes: Vec<u8>, usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents: &bytes,
                usage,
            })
        };
        let v3 = |v: &[glam::Vec3]| {
            v.iter()
                .flat_map(|p| p.to_array())
                .flat_map(f32::to_le_bytes)
                .collect::<Vec<u8>>()
        };
        let vertex = [v3(&pos), v3(&nor), v3(&cen)].map(|b| buffer(b, wgpu::BufferUsages::VERTEX));
        let index = buffer(
            idx.iter().flat_map(|i| i.to_le_bytes()).collect(),
            wgpu::BufferUsages::INDEX,
        );
        let (frame, material) = phong_shader::wgsl_buffers(scene, i);
        let frame = buffer(frame, wgpu::BufferUsages::UNIFORM);
        let material = buffer(material, wgpu::BufferUsages::UNIFORM);
        let attrs: Vec<[wgpu::VertexAttribute; 1]> = (0..3)
            .map(|k| {
                [wgpu::VertexAttribute {
                    format: wgpu::VertexFormat::Float32x3,
                    offset: 0,
                    shader_location: k,
                }]
            })
            .collect();
        let layouts: Vec<Option<wgpu::VertexBufferLayout>> = attrs
            .iter()
            .take(if flat { 3 } else { 2 })
            .map(|a| {
                Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: a,
                })
            })
            .collect();
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: None,
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &layouts,
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::TextureFormat::Rgba8Unorm.into())],
            }),
            primitive: wgpu::PrimitiveState {
                cull_mode: (!o.shading.options.two_sided).then_some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: frame.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: material.as_entire_binding(),
                },
            ],
        });
        draws.push((pipeline, group, vertex, index, idx.len() as u32, flat));
    }
    {
        let color_view = color.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: enc(bg[0]),
                        g: enc(bg[1]),
                        b: enc(bg[2]),
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        for (pipeline, group, vertex, index, count, flat) in &draws {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            for (k, b) in vertex.iter().enumerate().take(if *flat { 3 } else { 2 }) {
                pass.set_vertex_buffer(k as u32, b.slice(..));
            }
            pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..*count, 0, 0..1);
        }
    }
    let row = (w * 4).div_ceil(256) * 256;
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row * h),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        color.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([encoder.finish()]);
    readback.map_async(wgpu::MapMode::Read, .., |r| r.expect("mapped"));
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    let data = readback.get_mapped_range(..).expect("the mapped bytes");
    (0..h as usize)
        .flat_map(|y| data[y * row as usize..y * row as usize + w as usize * 4].to_vec())
        .collect()
}

#[test]
fn wgpu_draws_phongs_pixels_with_the_modules() {
    let Some((device, queue)) = device() else { return };
    for (what, scene) in scenes() {
        let ours = draw(&device, &queue, &scene);
        let mut renderer = phong_raster::Renderer::new();
        let options = phong_raster::RenderOptions::default();
        let (picture, _) =
            phong_run::draw(&scene, phong_run::Backend::Cpu(&options), &mut renderer).expect("phong's render");
        let theirs = picture.rgba8();
        let off = (0..ours.len() / 4)
            .filter(|&i| (0..3).any(|c| ours[i * 4 + c].abs_diff(theirs[i * 4 + c]) > 2))
            .count();
        let total = ours.len() / 4;
        // The objects are drawn: a tenth of the image at least is not the background.
        let drawn = (0..total).filter(|&i| ours[i * 4..i * 4 + 3] != ours[..3]).count();
        assert!(drawn * 10 >= total, "{what}: only {drawn} pixels drawn");
        eprintln!("{what:?}: {off} pixels past 2/255");
        assert!(off * 200 <= total, "{what}: {off} of {total} pixels past 2/255");
    }
}
