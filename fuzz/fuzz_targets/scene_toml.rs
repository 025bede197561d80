//! The TOML scene reader on any text: no panic, every error has a location, and an accepted
//! scene's meshes never come from disk here (a lookup that refuses).
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    let lookup = |_: &str| Err("no meshes while fuzzing".to_string());
    match phong_scene::parse_scene_with(src, Path::new("fuzz.toml"), Some(&lookup)) {
        Ok(loaded) => {
            // Limits hold for whatever was accepted.
            let s = &loaded.scene;
            assert!(s.image.width >= 1 && s.image.height >= 1);
            assert!(s.triangle_count() as u64 <= 1 << 24);
        }
        Err(phong_scene::Error::Parse { line, col, .. }) => assert!(line >= 1 && col >= 1),
        Err(e) => panic!("not a located error: {e}"),
    }
});
