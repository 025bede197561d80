// The render pipeline's entry points: the scene's triangles with per-object shading settings
// (object = instance index), drawn by the GPU's rasterizer.

struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // Flat shading: the triangle's centroid (its normal is then the facet normal).
    @location(2) centroid: vec3<f32>,
}

@vertex
fn vs_main(v: VsIn, @builtin(instance_index) object: u32) -> VsOut {
    return vertex(v.position, v.normal, v.centroid, object);
}

@fragment
fn fs_main(f: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Back faces are drawn only for two-sided objects (culled otherwise). Premultiplied by
    // alpha 1; the read-back divides by the resolved alpha (straight alpha).
    return vec4<f32>(fragment(f, !front), 1.0);
}
