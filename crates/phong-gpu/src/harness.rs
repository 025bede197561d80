//! The test harness: the WGSL shading function run on given points, for testing the port
//! against [`phong_core::shade`]. Not part of the renderer.

use crate::upload::{entries, non_empty};
use crate::{Error, Gpu, GpuCase, GpuGlobals, GpuLight, GpuObject, SHADE_CASES_WGSL};
use phong_core::{Color, Lighting, Material, Shading, ShadingSettings, SurfacePoint, View};
use wgpu::util::DeviceExt;

impl Gpu {
    /// Runs the WGSL shading function on `cases` in a compute pass: case `i` shades point
    /// `cases[i].0` with material `cases[i].1`, settings `cases[i].2` and view `cases[i].3`
    /// under `lighting`. For testing the WGSL port against [`phong_core::shade`].
    #[doc(hidden)]
    pub fn shade_cases(
        &self,
        lighting: &Lighting,
        cases: &[(SurfacePoint, Material, ShadingSettings, View)],
    ) -> Result<Vec<Shading>, Error> {
        let d = &self.device;
        let scopes = self.scopes();
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("phong shade cases"),
            source: wgpu::ShaderSource::Wgsl(SHADE_CASES_WGSL.into()),
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("phong shade cases"),
            layout: None,
            module: &module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let lights: Vec<GpuLight> = lighting.lights().iter().map(GpuLight::from).collect();
        let objects: Vec<GpuObject> = cases.iter().map(|(_, m, s, v)| GpuObject::new(m, s, v)).collect();
        let gcases: Vec<GpuCase> = cases
            .iter()
            .map(|(p, ..)| GpuCase {
                position: [p.position.x, p.position.y, p.position.z, 0.0],
                normal: [p.normal.x, p.normal.y, p.normal.z, 0.0],
            })
            .collect();
        let a = lighting.ambient();
        let globals = GpuGlobals {
            ambient: [a.r, a.g, a.b, 0.0],
            counts: [lights.len() as u32, cases.len() as u32, 0, 0],
        };
        let buf = |contents: &[u8], usage| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents,
                usage,
            })
        };
        let gb = buf(bytemuck::bytes_of(&globals), wgpu::BufferUsages::UNIFORM);
        let lb = buf(&non_empty(&lights), wgpu::BufferUsages::STORAGE);
        let ob = buf(&non_empty(&objects), wgpu::BufferUsages::STORAGE);
        let cb = buf(&non_empty(&gcases), wgpu::BufferUsages::STORAGE);
        let size = (cases.len().max(1) * 64) as u64;
        let rb = d.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let out = d.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries(&[&gb, &lb, &ob, &cb, &rb]),
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
        }
        enc.copy_buffer_to_buffer(&rb, 0, &out, 0, size);
        self.queue.submit([enc.finish()]);
        let floats: Vec<f32> = self.read_buffer(&out, scopes, "shading test cases")?;
        let c = |i: usize| Color::new(floats[i], floats[i + 1], floats[i + 2]);
        Ok((0..cases.len())
            .map(|k| Shading {
                ambient: c(k * 16),
                diffuse: c(k * 16 + 4),
                specular: c(k * 16 + 8),
                color: c(k * 16 + 12),
            })
            .collect())
    }
}
