//! The one place for phong's magic numbers, each with its reason
//! (llvmpipe's `lp_limits.h` style).

/// Largest image width or height in pixels. 16384 is the largest texture
/// size GPUs guarantee (wgpu's `max_texture_dimension_2d` on most adapters)
/// and keeps the rasteriser's fixed-point products inside `i64` with margin:
/// with [`GUARD_BAND`] and [`SUBPIXEL_BITS`], `|X| < 2.5·16384·256 < 2^24`.
pub const MAX_IMAGE_DIMENSION: u32 = 16384;

/// Largest number of pixels in one image (times samples, see
/// [`MAX_SAMPLES_TOTAL`]): 16384², so a full-size image fits in memory.
pub const MAX_SAMPLES_TOTAL: u64 = 16384 * 16384 * 4;

/// Sub-pixel precision of snapped vertex positions: 8 bits (1/256 pixel),
/// as D3D11 and llvmpipe.
pub const SUBPIXEL_BITS: u32 = 8;

/// Guard band, in units of the viewport's half extent: triangles are
/// clipped against `|x|, |y| <= GUARD_BAND · w` instead of the viewport, so
/// that almost no triangle needs clipping in x and y while screen
/// coordinates stay bounded for the fixed-point rasteriser.
pub const GUARD_BAND: f32 = 4.0;

/// Tile size of the rasteriser, in pixels: 64 × 64 keeps one tile's colour
/// and depth samples (64·64·16·20 bytes at 16 samples) in L2.
pub const TILE_SIZE: u32 = 64;

/// Most rendering threads one may ask for: a thread per core of the largest machines, far
/// below where spawning fails (100 000 threads exhausted this machine's memory instead of
/// returning an error).
pub const MAX_THREADS: usize = 1024;

/// Most lights in one scene (the GPU backend's storage buffer is sized from it).
pub const MAX_LIGHTS: usize = 1024;

/// Most segments for a tessellated primitive (4096² quads is already 33M triangles).
pub const MAX_SEGMENTS: u32 = 4096;

/// Most triangles one tessellated primitive may have (16M: about 1.5 GiB of
/// mesh and transformed vertices), so that a large `segments` is an error,
/// not an out-of-memory abort.
pub const MAX_PRIMITIVE_TRIANGLES: u64 = 1 << 24;

/// Sample positions within a pixel, in [0, 1)². One: the centre. Four: the D3D/Vulkan
/// standard rotated grid. Sixteen: a 4×4 grid. The CPU renderer and the GPU's compute
/// rasterizer sample here.
pub fn sample_pattern(samples: crate::Samples) -> Vec<(f32, f32)> {
    match samples {
        crate::Samples::Four => [(-2.0, -6.0), (6.0, -2.0), (-6.0, 2.0), (2.0, 6.0)]
            .iter()
            .map(|&(x, y)| (0.5 + x / 16.0, 0.5 + y / 16.0))
            .collect(),
        crate::Samples::Sixteen => (0..16)
            .map(|i| ((i % 4) as f32 * 0.25 + 0.125, (i / 4) as f32 * 0.25 + 0.125))
            .collect(),
        crate::Samples::One => vec![(0.5, 0.5)],
    }
}

/// `phong serve`: largest request body of a scene or probe (JSON), in bytes. The page's
/// scenes are a few kilobytes; 1 MiB leaves room for scripted scenes with many objects and
/// inline materials, while a client cannot make the server buffer more.
pub const SERVE_MAX_BODY: usize = 1 << 20;

/// `phong serve`: most pixels of one rendered image. 3840 × 2160 (a 4K screen) is more than
/// any browser viewport, and keeps a frame's CPU time within an interactive budget.
pub const SERVE_MAX_PIXELS: u64 = 3840 * 2160;

/// `phong serve`: most samples (pixels times antialias samples) of one image: 4K at 4
/// samples, so that one request's sample buffers (about 20 bytes each) stay under 1 GiB.
pub const SERVE_MAX_SAMPLES: u64 = 3840 * 2160 * 4;

/// `phong serve`: most triangles of one scene (uploads included): 4M triangles render in
/// well under a second on two cores, and its meshes take about 400 MB.
pub const SERVE_MAX_TRIANGLES: u64 = 1 << 22;

/// `phong serve`: most lights of one scene. The page lists each light's controls; 16 is
/// OpenGL 2.1's usual implementation count doubled.
pub const SERVE_MAX_LIGHTS: usize = 16;

/// `phong serve`: largest uploaded file (an OBJ or MTL), in bytes: a 1M-triangle OBJ is about
/// 60 MB of text.
pub const SERVE_MAX_UPLOAD: usize = 64 << 20;

/// `phong serve`: most files one client keeps uploaded (an OBJ with its MTL libraries).
pub const SERVE_MAX_UPLOADS: usize = 16;

/// `phong serve`: most bytes of uploads per client, summed: bounds the memory a client holds.
pub const SERVE_MAX_UPLOAD_TOTAL: usize = 128 << 20;

/// `phong serve`: most clients holding uploads at once (each up to [`SERVE_MAX_UPLOAD_TOTAL`]);
/// with the idle timeout, bounds the server's upload memory to 2 GiB.
pub const SERVE_MAX_CLIENTS: usize = 16;

/// `phong serve`: seconds after which an idle client's uploads are dropped.
pub const SERVE_IDLE_SECONDS: u64 = 30 * 60;

/// `phong serve`: renders (and probes) in flight for one client. The page keeps at most one
/// frame and one probe in flight, or the Terms view's four images; 6 leaves room for both.
pub const SERVE_RENDERS_PER_CLIENT: usize = 6;

/// `phong serve`: renders in flight in all; more wait for none: they answer 503 at once,
/// because a queued frame is a stale frame for an interactive client.
pub const SERVE_RENDERS_TOTAL: usize = 32;

/// `phong serve`: largest body of a fit request (the scene and a base64 target PNG): a
/// 1920×1080 photograph as PNG is up to about 8 MB, 11 MB in base64.
pub const SERVE_MAX_FIT_BODY: usize = 16 << 20;

/// Largest scene file (TOML) read, in bytes: scenes are a few kilobytes of text; 16 MiB leaves
/// room for generated scenes with thousands of objects and stops `/dev/zero`-like inputs early.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Largest OBJ file read, in bytes: an OBJ of [`MAX_SCENE_TRIANGLES`] triangles with normals and
/// texture coordinates is about 1.5 GB; 1 GiB of text keeps the read and its parse in memory.
pub const MAX_MODEL_BYTES: u64 = 1 << 30;

/// Largest MTL file read, in bytes: material libraries are kilobytes.
pub const MAX_MTL_BYTES: u64 = 16 << 20;

/// Largest image read as a fit's target or mask, in bytes: a 16384² RGBA 16-bit PNG barely
/// compressed is 2 GiB; 512 MiB covers any photograph.
pub const MAX_IMAGE_FILE_BYTES: u64 = 512 << 20;

/// Most triangles in one scene, all shapes and meshes together (16M: about 1.5 GiB of meshes
/// and transformed vertices), checked as each object is read, before its mesh is built.
pub const MAX_SCENE_TRIANGLES: u64 = 1 << 24;

/// Longest side of a texture, in texels (OpenGL implementations allow 16384 or 32768).
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// Most bytes of textures, mipmaps included, in one texture and in one scene: 8 bytes a texel
/// (16-bit RGBA) with mipmaps is 2 GiB at about 11585² texels (an 8K texture takes 512 MiB).
pub const MAX_TEXTURE_BYTES: u64 = 2 << 30;
