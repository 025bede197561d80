//! The OBJ/MTL reader on any text: the input is split at the first NULs into an OBJ, its
//! `mtllib` (whatever name it gives) and the bytes of every texture image its maps name; no
//! panic (tobj's, the image decoders' included), every error located.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let mut pieces = data.splitn(3, |&b| b == 0);
    let (obj, mtl, image) = (
        pieces.next().unwrap_or_default(),
        pieces.next().unwrap_or_default(),
        pieces.next().unwrap_or_default(),
    );
    let (Ok(obj), Ok(mtl)) = (std::str::from_utf8(obj), std::str::from_utf8(mtl)) else {
        return;
    };
    // Every MTL library the OBJ names is `mtl`, every image `image`.
    let resource = |name: &str| {
        Ok(if name.to_ascii_lowercase().ends_with(".mtl") { mtl.as_bytes() } else { image }.to_vec())
    };
    match phong_scene::ModelFile::from_bytes(Path::new("fuzz.obj"), obj.as_bytes(), &resource) {
        Ok(model) => assert!(!model.parts.is_empty()),
        Err(phong_scene::Error::Parse { line, col, .. }) => assert!(line >= 1 && col >= 1),
        Err(e) => panic!("not a located error: {e}"),
    }
});
