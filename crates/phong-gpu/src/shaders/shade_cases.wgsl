// The shading function alone, for the tests: case i shades cases[i] with objects[i].

struct Case {
    position: vec4<f32>,
    normal: vec4<f32>,
}

struct CaseOut {
    ambient: vec4<f32>,
    diffuse: vec4<f32>,
    specular: vec4<f32>,
    color: vec4<f32>,
}

struct Globals {
    ambient: vec4<f32>,
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> objects: array<ObjectParams>;
@group(0) @binding(3) var<storage, read> cases: array<Case>;
@group(0) @binding(4) var<storage, read_write> results: array<CaseOut>;

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= globals.counts.y) {
        return;
    }
    let o = objects[i];
    let sh = shade(cases[i].position.xyz, cases[i].normal.xyz, o.material, o.options, globals.ambient.xyz, globals.counts.x);
    results[i] = CaseOut(vec4<f32>(sh.ambient, 0.0), vec4<f32>(sh.diffuse, 0.0), vec4<f32>(sh.specular, 0.0), vec4<f32>(sh.color, 0.0));
}
