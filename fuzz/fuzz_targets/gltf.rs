//! The glTF reader on any bytes, named `.gltf` or `.glb` by the first byte (external buffers
//! are refused, data URIs and the GLB chunk are read): no panic, every error a model error
//! naming the file, every accepted model a valid mesh.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let name = ["fuzz.gltf", "fuzz.glb"][usize::from(pick % 2)];
    let none = |uri: &str| Err(format!("{uri} is not available here"));
    match phong_scene::ModelFile::from_bytes(Path::new(name), bytes, &none) {
        Ok(model) => {
            for p in model.parts {
                let n = p.mesh.positions().len() as u32;
                assert!(p.mesh.triangles().iter().flatten().all(|&i| i < n));
                assert!(p.mesh.positions().iter().all(|v| v.is_finite()));
            }
        }
        Err(e @ phong_scene::Error::Model { .. }) => assert!(e.to_string().starts_with(name)),
        Err(e) => panic!("not a model error: {e}"),
    }
});
