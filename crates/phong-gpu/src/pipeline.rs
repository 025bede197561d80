//! The render pipeline path: the GPU's own rasterizer with a `Depth32Float` depth buffer and
//! MSAA, one draw per object in the scene's draw order (instance index = its place there),
//! pipelines cached per (samples, cull, blend); a blended object's pipeline blends
//! premultiplied colours over the target (`ONE`, `ONE_MINUS_SRC_ALPHA`) without writing depth.

use crate::upload::{Upload, entries, non_empty};
use crate::{COLOR_FORMAT, DEPTH_FORMAT, Drawing, Gpu, GpuVertex};

impl Gpu {
    /// The pipeline's buffers, bind group and targets for `upload`.
    pub(crate) fn prepare_pipeline(
        &self,
        upload: Upload,
        scene_maps: Vec<(phong_core::Maps, bool, bool, f32)>,
    ) -> Drawing {
        let Upload {
            width,
            height,
            samples,
            geometry,
            frame,
            lights,
            objects,
            ..
        } = upload;
        let vb = self.buffer_init("vertices", &non_empty(&geometry.vertices), wgpu::BufferUsages::VERTEX);
        let ib = self.buffer_init("indices", &non_empty(&geometry.indices), wgpu::BufferUsages::INDEX);
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("phong frame"),
            layout: &self.layout,
            entries: &entries(&[&frame, &lights, &objects]),
        });
        let maps = self.map_bind_groups(&scene_maps);
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let n = samples.count();
        let msaa = (n > 1).then(|| self.texture("msaa", (width, height), COLOR_FORMAT, n, attachment));
        let depth = self.texture("depth", (width, height), DEPTH_FORMAT, n, attachment);
        Drawing::Pipeline {
            vb,
            ib,
            bind,
            maps,
            msaa_view: msaa.as_ref().map(|t| t.create_view(&Default::default())),
            depth_view: depth.create_view(&Default::default()),
            draws: geometry.draws,
            pipelines: Box::new([
                self.pipeline(n, false, false),
                self.pipeline(n, true, false),
                self.pipeline(n, false, true),
                self.pipeline(n, true, true),
            ]),
        }
    }

    /// The render pipeline for `samples` per pixel, culling back faces with `cull`, blending
    /// with `blend` (cached).
    fn pipeline(&self, samples: u32, cull: bool, blend: bool) -> wgpu::RenderPipeline {
        let mut cache = self.pipelines.lock().unwrap_or_else(|p| p.into_inner());
        cache
            .entry((samples, cull, blend))
            .or_insert_with(|| {
                let attributes =
                    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x4, 4 => Float32x3, 5 => Float32x4];
                self.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("phong"),
                    layout: Some(&self.pipeline_layout),
                    vertex: wgpu::VertexState {
                        module: &self.module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[Some(wgpu::VertexBufferLayout {
                            array_stride: std::mem::size_of::<GpuVertex>() as u64,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &attributes,
                        })],
                    },
                    primitive: wgpu::PrimitiveState {
                        topology: wgpu::PrimitiveTopology::TriangleList,
                        front_face: wgpu::FrontFace::Ccw,
                        cull_mode: cull.then_some(wgpu::Face::Back),
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(!blend),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: wgpu::MultisampleState {
                        count: samples,
                        mask: !0,
                        alpha_to_coverage_enabled: false,
                    },
                    fragment: Some(wgpu::FragmentState {
                        module: &self.module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format: COLOR_FORMAT,
                            blend: blend.then_some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            })
            .clone()
    }
}
