//! Reading back: mapped buffers (counters, timestamps, the shading harness's results) and the
//! drawn image, converted from half floats to a straight-alpha linear [`Image`].

use crate::device::Scopes;
use crate::{Error, Gpu, Prepared};
use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
use phong_core::Image;

impl Gpu {
    /// Maps `buffer` (a copy into it submitted), waits for the GPU, checks `scopes`, and
    /// returns its contents.
    pub(crate) fn read_buffer<T: bytemuck::Pod>(
        &self,
        buffer: &wgpu::Buffer,
        scopes: Scopes,
        doing: &'static str,
    ) -> Result<Vec<T>, Error> {
        self.read_mapped(buffer, scopes, doing, |data| bytemuck::pod_collect_to_vec(data))
    }

    /// [`Gpu::read_buffer`], `f` reading the mapped bytes in place.
    pub(crate) fn read_mapped<R>(
        &self,
        buffer: &wgpu::Buffer,
        scopes: Scopes,
        doing: &'static str,
        f: impl FnOnce(&[u8]) -> R,
    ) -> Result<R, Error> {
        let (tx, rx) = std::sync::mpsc::channel();
        buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.wait(doing)?;
        self.check(scopes, doing)?;
        rx.recv()
            .map_err(|e| self.fail(doing, e.to_string()))?
            .map_err(|e| self.fail(doing, e.to_string()))?;
        let out = {
            let data = buffer
                .get_mapped_range(..)
                .map_err(|e| self.fail(doing, e.to_string()))?;
            f(&data[..])
        };
        buffer.unmap();
        Ok(out)
    }

    /// Reads a drawn frame back into a straight-alpha linear image.
    pub fn read(&self, p: &Prepared) -> Result<Image, Error> {
        let (w, h) = (p.width, p.height);
        let d = &self.device;
        let scopes = self.scopes();
        let row = u64::from(w) * 8;
        let align = u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let padded = row.div_ceil(align) * align;
        self.check_limit(
            "read-back buffer bytes",
            padded * u64::from(h),
            self.limits.max_buffer_size,
        )?;
        let out = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: padded * u64::from(h),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = d.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &p.resolved,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &out,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([enc.finish()]);
        // Row by row from the mapping: each row's halves converted by `half` (F16C where the
        // processor has it) into a small buffer, then made straight alpha into the image, not
        // whole-frame copies (BENCHMARKS.md, G1).
        let bg = p.background;
        let stride = padded as usize;
        let pixels = self.read_mapped(&out, scopes, "reading the image back", |data| {
            let mut pixels = Vec::with_capacity(w as usize * h as usize);
            let mut floats = vec![0f32; 4 * w as usize];
            for y in 0..h as usize {
                let halves: Vec<u16> = bytemuck::pod_collect_to_vec(&data[y * stride..y * stride + row as usize]);
                halves.reinterpret_cast::<half::f16>().convert_to_f32_slice(&mut floats);
                pixels.extend(floats.chunks_exact(4).map(|c| {
                    if c[3] == 1.0 {
                        [c[0], c[1], c[2], 1.0]
                    } else if c[3] > 0.0 {
                        [c[0] / c[3], c[1] / c[3], c[2] / c[3], c[3]]
                    } else {
                        [bg[0], bg[1], bg[2], 0.0]
                    }
                }));
            }
            pixels
        })?;
        Ok(Image::from_pixels(w, h, pixels)?)
    }
}
