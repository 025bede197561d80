//! Uploading a scene: checks of the image against the device, the choice of path, the
//! geometry (smooth objects indexed, flat objects de-indexed with centroids), and the buffers
//! and targets both paths share; then the path's own preparation ([`crate::pipeline`],
//! [`crate::compute`]).

use crate::compute::Kernel;
use crate::{COLOR_FORMAT, Drawing, Error, Gpu, GpuFrame, GpuLight, GpuObject, GpuPath, GpuVertex, Prepared};
use phong_core::mesh::facet_normal;
use phong_core::{Interpolation, Samples, Scene};
use wgpu::util::DeviceExt;

/// Bind group entries for `buffers`, bound at 0, 1, 2, … in order.
pub(crate) fn entries<'a>(buffers: &[&'a wgpu::Buffer]) -> Vec<wgpu::BindGroupEntry<'a>> {
    buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect()
}

/// Storage buffers may not be empty: pad with one zeroed element.
pub(crate) fn non_empty<T: bytemuck::Pod + bytemuck::Zeroable>(v: &[T]) -> Vec<u8> {
    if v.is_empty() {
        bytemuck::bytes_of(&T::zeroed()).to_vec()
    } else {
        bytemuck::cast_slice(v).to_vec()
    }
}

/// The scene's geometry in one vertex buffer for all objects (indices absolute).
pub(crate) struct Geometry {
    pub vertices: Vec<GpuVertex>,
    /// Each vertex's object.
    pub vertex_object: Vec<u32>,
    pub indices: Vec<u32>,
    /// Each object's index range, whether back faces are culled, and whether it is blended;
    /// in the scene's draw order (`Scene::draw_order`), which is also the objects' order here.
    pub draws: Vec<(std::ops::Range<u32>, bool, bool)>,
    /// The scene's object drawn `k`-th.
    pub order: Vec<usize>,
    pub objects: Vec<GpuObject>,
}

impl Geometry {
    fn of(scene: &Scene) -> Geometry {
        let mut g = Geometry {
            vertices: Vec::new(),
            vertex_object: Vec::new(),
            indices: Vec::new(),
            draws: Vec::new(),
            objects: Vec::with_capacity(scene.objects.len()),
            order: scene.draw_order(),
        };
        for (i, &k) in g.order.clone().iter().enumerate() {
            let o = &scene.objects[k];
            let view = scene.camera.view(o.shading.viewer);
            g.objects.push(GpuObject::new(&o.material, &o.shading, &view));
            // (A flat mesh's triangles with vertices of their own: a vertex carries its normal.)
            let m = o.mesh.with_vertex_normals();
            let base = g.vertices.len();
            let first = g.indices.len() as u32;
            let uv = |k: u32| {
                let set = |s: &[glam::Vec2]| s.get(k as usize).map_or([0.0; 2], |u| u.to_array());
                let ([a, b], [c, d]) = (set(m.uvs()), set(m.uvs1()));
                [a, b, c, d]
            };
            let color = |k: u32| m.colors().get(k as usize).map_or([1.0; 3], |c| c.to_array());
            let tangent = |k: u32| m.tangents().get(k as usize).map_or([0.0; 4], |t| t.to_array());
            if o.shading.interpolation == Interpolation::Flat {
                for (t, corners) in m.triangles().iter().enumerate() {
                    let [a, b, c] = m.corners(t);
                    let n = facet_normal(a, b, c).to_array();
                    let centroid = ((a + b + c) / 3.0).to_array();
                    for (p, k) in [a, b, c].into_iter().zip(corners) {
                        g.indices.push(g.vertices.len() as u32);
                        g.vertices.push(GpuVertex {
                            position: p.to_array(),
                            normal: n,
                            centroid,
                            uv: uv(*k),
                            color: color(*k),
                            tangent: tangent(*k),
                        });
                    }
                }
            } else {
                g.vertices.extend(
                    (0u32..)
                        .zip(m.positions().iter().zip(m.normals()))
                        .map(|(k, (p, n))| GpuVertex {
                            position: p.to_array(),
                            normal: n.to_array(),
                            centroid: p.to_array(),
                            uv: uv(k),
                            color: color(k),
                            tangent: tangent(k),
                        }),
                );
                g.indices
                    .extend(m.triangles().iter().flatten().map(|&k| k + base as u32));
            }
            g.vertex_object.resize(g.vertices.len(), i as u32);
            g.draws
                .push((first..g.indices.len() as u32, !o.shading.options.two_sided, o.blends()));
        }
        g
    }

    /// Triangles drawn.
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }
}

/// What both paths' preparations receive: the scene's size, its geometry, and the uniform
/// and storage buffers of the frame, lights and objects.
pub(crate) struct Upload {
    pub width: u32,
    pub height: u32,
    pub samples: Samples,
    pub geometry: Geometry,
    /// The background, premultiplied (the targets' clear value).
    pub premultiplied: [f32; 4],
    pub frame: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub objects: wgpu::Buffer,
}

impl Upload {
    /// Pixels × samples.
    pub fn samples_total(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height) * u64::from(self.samples.count())
    }
}

impl Gpu {
    /// A buffer holding `contents`.
    pub(crate) fn buffer_init(&self, label: &'static str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    }

    /// An uninitialised buffer of `size` bytes (at least 16).
    pub(crate) fn buffer(&self, label: &'static str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage,
            mapped_at_creation: false,
        })
    }

    /// A 2D texture of `(w, h)` pixels.
    pub(crate) fn texture(
        &self,
        label: &'static str,
        (w, h): (u32, u32),
        format: wgpu::TextureFormat,
        samples: u32,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: samples,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    }

    /// Uploads `scene` (buffers, targets, bind groups) for [`Gpu::draw`], on the path set by
    /// [`Gpu::set_path`].
    pub fn prepare(&self, scene: &Scene) -> Result<Prepared, Error> {
        self.prepare_path(scene, self.path)
    }

    /// [`Gpu::prepare`] on the given path.
    pub fn prepare_path(&self, scene: &Scene, path: GpuPath) -> Result<Prepared, Error> {
        scene.image.check()?;
        let (w, h, samples) = (scene.image.width, scene.image.height, scene.image.samples);
        let samples_total = scene.image.samples_total();
        let max_tex = u64::from(self.limits.max_texture_dimension_2d);
        self.check_limit("image width", u64::from(w), max_tex)?;
        self.check_limit("image height", u64::from(h), max_tex)?;
        for o in scene.objects.iter().filter(|o| o.textured()) {
            for m in o.maps.each() {
                let side = m.texture.width().max(m.texture.height());
                self.check_limit("texture side", u64::from(side), max_tex)?;
            }
        }
        self.check_lost("starting a render")?;
        let compute = match path {
            GpuPath::Pipeline => false,
            GpuPath::Auto if self.is_cpu_adapter() => false,
            // A driver that cannot build the compute rasterizer leaves the pipeline.
            GpuPath::Auto | GpuPath::PreferCompute => self.compute_reason(scene).is_none() && self.kernels().is_ok(),
            GpuPath::Compute => match self.compute_reason(scene) {
                None => true,
                Some(why) => return Err(Error::Compute(why)),
            },
        };
        let geometry = Geometry::of(scene);
        let max_buf = self.max_storage_bytes();
        let vertex_limit = if compute { max_buf } else { self.limits.max_buffer_size };
        let vertex_bytes = (geometry.vertices.len() * size_of::<GpuVertex>()) as u64;
        self.check_limit("vertex buffer bytes", vertex_bytes, vertex_limit)?;
        self.check_limit("index buffer bytes", (geometry.indices.len() * 4) as u64, vertex_limit)?;
        let lights: Vec<GpuLight> = scene.lighting.lights().iter().map(GpuLight::from).collect();
        self.check_limit("lights", (lights.len() * size_of::<GpuLight>()) as u64, max_buf)?;
        if compute {
            self.check_limit("visibility buffer bytes", samples_total * 8, max_buf)?;
            let colour_bytes = geometry.vertices.len() as u64 * size_of::<[[f32; 4]; 4]>() as u64;
            self.check_limit("per-vertex colour bytes", colour_bytes, max_buf)?;
        }
        let cam = &scene.camera;
        let ambient = scene.lighting.ambient();
        let frame = GpuFrame {
            clip_from_world: cam.clip_from_world(w as f32 / h as f32).to_cols_array(),
            eye: [cam.eye().x, cam.eye().y, cam.eye().z, cam.near()],
            forward: [cam.forward().x, cam.forward().y, cam.forward().z, cam.far()],
            ambient: [ambient.r, ambient.g, ambient.b, 0.0],
            counts: [lights.len() as u32, 0, 0, 0],
        };
        let bg = scene.image.background;
        let scopes = self.scopes();
        let storage = wgpu::BufferUsages::STORAGE;
        let upload = Upload {
            width: w,
            height: h,
            samples,
            premultiplied: [bg[0] * bg[3], bg[1] * bg[3], bg[2] * bg[3], bg[3]],
            frame: self.buffer_init("frame", bytemuck::bytes_of(&frame), wgpu::BufferUsages::UNIFORM),
            lights: self.buffer_init("lights", &non_empty(&lights), storage),
            objects: self.buffer_init("objects", &non_empty(&geometry.objects), storage),
            geometry,
        };
        let target = if compute {
            wgpu::TextureUsages::STORAGE_BINDING
        } else {
            wgpu::TextureUsages::RENDER_ATTACHMENT
        };
        let resolved = self.texture(
            "resolved",
            (w, h),
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::COPY_SRC | target,
        );
        let resolved_view = resolved.create_view(&Default::default());
        let passes = if compute { Kernel::STAGES } else { 1 };
        let timing = self.has_timestamps().then(|| {
            let set = self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("phong pass times"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * passes,
            });
            let usage = wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC;
            (set, self.buffer("pass times", 16 * u64::from(passes), usage))
        });
        let feedback = self.buffer(
            "feedback",
            16 + 16 * u64::from(passes),
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        );
        let triangles = upload.geometry.triangles();
        let premultiplied = upload.premultiplied;
        let drawing: Drawing = if compute {
            self.prepare_compute(upload, &resolved_view)?
        } else {
            let maps = upload
                .geometry
                .order
                .iter()
                .map(|&k| {
                    let o = &scene.objects[k];
                    let maps = if o.textured() {
                        o.maps.clone()
                    } else {
                        phong_core::Maps {
                            blend: o.maps.blend,
                            ..Default::default()
                        }
                    };
                    (maps, o.blends(), !o.mesh.colors().is_empty(), o.material.alpha())
                })
                .collect();
            self.prepare_pipeline(upload, maps)
        };
        self.check(scopes, "preparing the frame")?;
        Ok(Prepared {
            width: w,
            height: h,
            background: bg,
            premultiplied,
            triangles,
            resolved,
            resolved_view,
            timing,
            feedback,
            passes,
            drawing,
        })
    }
}
