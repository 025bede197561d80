//! # phong-run
//!
//! One render, from what a user names to pixels: a scene file, a model file or a scene
//! document ([`Source`]) loaded, the user's settings applied ([`Settings`]: size, samples, the
//! shading overrides, a model's view, scene tables merged over the scene), then drawn on the
//! CPU or the GPU with the scene's labels ([`draw`]), ready to encode as the PNG `phong render`
//! writes. `phong render`, `phong batch` and the Python module all call it, so that they draw
//! the same pixels. Model files can be read once and viewed many times through [`Models`].

mod built;
mod error;
mod frame;
mod models;
mod request;

pub use built::Built;
pub use error::{Error, message};
pub use frame::{Backend, Picture, Stats, draw, draw_linear};
pub use models::Models;
pub use phong_raster::Pool;
pub use request::{Settings, Source, load, load_viewed, merge_tables, view_options};
