//! The OBJ/MTL reader on any text: the input is split at the first NUL into an OBJ and its
//! `mtllib` (whatever name it gives); no panic (tobj's included), every error located.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &b""[..]),
    };
    let (Ok(obj), Ok(mtl)) = (std::str::from_utf8(obj), std::str::from_utf8(mtl)) else {
        return;
    };
    let read = |_: &Path| Ok(mtl.to_string());
    let mut warnings = Vec::new();
    match phong_scene::load_obj_text(Path::new("fuzz.obj"), obj, &read, &mut warnings) {
        Ok(parts) => assert!(!parts.is_empty()),
        Err(phong_scene::Error::Parse { line, col, .. }) => assert!(line >= 1 && col >= 1),
        Err(e) => panic!("not a located error: {e}"),
    }
});
