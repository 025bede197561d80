//! Drawing a prepared frame: one command buffer (the pipeline's render pass, or the compute
//! rasterizer's dispatches), submitted and waited for, with its timestamps and the compute
//! path's overflow flag read back.

use crate::compute::ComputeStage;
use crate::{Drawing, Drawn, Error, Gpu, Prepared};
use std::time::{Duration, Instant};

impl Gpu {
    /// Draws a prepared frame and waits for it: wall-clock time, the GPU's own time, and
    /// whether the compute rasterizer's tile list overflowed (the image is then incomplete).
    pub fn draw(&self, p: &Prepared) -> Result<Drawn, Error> {
        self.draw_timed(p, false)
    }

    /// [`Gpu::draw`], the compute rasterizer's kernels each in its own timed pass
    /// ([`Drawn::stages`]). The passes' boundaries cost time of their own, so frames are timed
    /// whole by [`Gpu::draw`].
    pub fn draw_stages(&self, p: &Prepared) -> Result<Drawn, Error> {
        self.draw_timed(p, true)
    }

    fn draw_timed(&self, p: &Prepared, per_kernel: bool) -> Result<Drawn, Error> {
        let per_kernel = per_kernel && matches!(p.drawing, Drawing::Compute { .. });
        let passes = if per_kernel { p.passes } else { 1 };
        let scopes = self.scopes();
        let t1 = Instant::now();
        let mut enc = self.device.create_command_encoder(&Default::default());
        match &p.drawing {
            Drawing::Pipeline {
                vb,
                ib,
                bind,
                maps,
                msaa_view,
                depth_view,
                draws,
                pipelines,
            } => {
                let (view, resolve_target) = match msaa_view {
                    Some(m) => (m, Some(&p.resolved_view)),
                    None => (&p.resolved_view, None),
                };
                let bg = p.premultiplied.map(f64::from);
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("phong"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color {
                                r: bg[0],
                                g: bg[1],
                                b: bg[2],
                                a: bg[3],
                            }),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Discard,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: p.timing.as_ref().map(|(set, _)| wgpu::RenderPassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }),
                    ..Default::default()
                });
                pass.set_bind_group(0, bind, &[]);
                pass.set_vertex_buffer(0, vb.slice(..));
                pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
                for (i, (range, cull, blend)) in draws.iter().enumerate() {
                    if range.is_empty() {
                        continue;
                    }
                    pass.set_pipeline(&pipelines[2 * usize::from(*blend) + usize::from(*cull)]);
                    pass.set_bind_group(1, &maps[i], &[]);
                    pass.draw_indexed(range.clone(), 0, i as u32..i as u32 + 1);
                }
            }
            Drawing::Compute {
                stages,
                counter,
                dispatch,
                ..
            } => {
                // One pass (wgpu puts barriers between its dispatches), or one per kernel.
                let groups: Vec<&[ComputeStage]> = if per_kernel {
                    stages.chunks(1).collect()
                } else {
                    vec![&stages[..]]
                };
                for (i, group) in (0u32..).zip(groups) {
                    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("phong compute rasterizer"),
                        timestamp_writes: p.timing.as_ref().map(|(set, _)| wgpu::ComputePassTimestampWrites {
                            query_set: set,
                            beginning_of_pass_write_index: Some(2 * i),
                            end_of_pass_write_index: Some(2 * i + 1),
                        }),
                    });
                    for s in group {
                        pass.set_pipeline(&s.pipeline);
                        pass.set_bind_group(0, &s.bind, &[]);
                        match s.groups {
                            Ok((x, y)) => pass.dispatch_workgroups(x, y, 1),
                            Err(offset) => pass.dispatch_workgroups_indirect(dispatch, offset),
                        }
                    }
                }
                enc.copy_buffer_to_buffer(counter, 0, &p.feedback, 0, 16);
            }
        }
        if let Some((set, resolved)) = &p.timing {
            enc.resolve_query_set(set, 0..2 * passes, resolved, 0);
            enc.copy_buffer_to_buffer(resolved, 0, &p.feedback, 16, 16 * u64::from(passes));
        }
        self.queue.submit([enc.finish()]);
        let words: Vec<u32> = self.read_buffer(&p.feedback, scopes, "rendering")?;
        let wall = t1.elapsed();
        let overflow_flag = words[2];
        let ticks: Vec<u64> = words[4..]
            .chunks_exact(2)
            .map(|w| u64::from(w[0]) | u64::from(w[1]) << 32)
            .collect();
        // Ticks × period (ns per tick); a counter that went backwards gives none.
        let period = f64::from(self.queue.get_timestamp_period());
        let span = |a: u64, b: u64| Some(Duration::from_secs_f64(b.checked_sub(a)? as f64 * period * 1e-9));
        let (gpu, stages) = match &p.timing {
            None => (None, Vec::new()),
            Some(_) => {
                let ticks = &ticks[..2 * passes as usize];
                let stages = match &p.drawing {
                    Drawing::Compute { stages, .. } if per_kernel => stages
                        .iter()
                        .zip(ticks.chunks_exact(2))
                        .filter_map(|(s, t)| Some((s.kernel.name(), span(t[0], t[1])?)))
                        .collect(),
                    _ => Vec::new(),
                };
                (span(ticks[0], ticks[ticks.len() - 1]), stages)
            }
        };
        let overflowed = matches!(p.drawing, Drawing::Compute { .. }) && overflow_flag != 0;
        Ok(Drawn {
            wall,
            gpu,
            stages,
            overflowed,
        })
    }
}
