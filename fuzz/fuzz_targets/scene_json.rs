//! The server's JSON scene reader on any JSON: no panic, and the TOML text it writes for the
//! reader is always a valid TOML file.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(value) = serde_json::from_slice::<serde_json::Value>(data) else {
        return;
    };
    let lookup = |_: &str| Err("no meshes while fuzzing".to_string());
    if let Ok(toml) = phong_scene::json_to_toml(&value) {
        // The TOML text is a TOML file: the JSON round-trips through it.
        assert!(
            toml.text.parse::<toml::Table>().is_ok() || toml.text.is_empty(),
            "{}",
            toml.text
        );
    }
    let _ = phong_scene::parse_scene_json(&value, &lookup);
});
