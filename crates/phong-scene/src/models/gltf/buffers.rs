//! A glTF file's bytes: its buffers (the GLB's chunk, data URIs, files), accessors checked
//! against them before the `gltf` crate reads them, and tightly packed arrays read as slices.

use crate::Error;
use base64::Engine;
use std::borrow::Cow;

/// A buffer's bytes: the GLB's binary chunk borrowed from the file, others owned.
pub(super) type Buffer<'b> = Cow<'b, [u8]>;

/// The file's buffers: the GLB's binary chunk, base64 data URIs, and files read by `resource`;
/// each at least as long as the file says.
pub(super) fn load_buffers<'b>(
    doc: &::gltf::Document,
    bin: Option<Cow<'b, [u8]>>,
    resource: &dyn Fn(&str) -> Result<Vec<u8>, String>,
    fail: &dyn Fn(String) -> Error,
) -> Result<Vec<Buffer<'b>>, Error> {
    let mut buffers: Vec<Buffer> = Vec::new();
    for b in doc.buffers() {
        let data: Buffer = match b.source() {
            ::gltf::buffer::Source::Bin => bin.clone().ok_or_else(|| {
                fail(format!(
                    "buffer {} is the GLB's binary chunk, which is missing",
                    b.index()
                ))
            })?,
            ::gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, data) = rest
                        .split_once(";base64,")
                        .ok_or_else(|| fail(format!("buffer {}: a data URI that is not base64", b.index())))?;
                    Cow::Owned(
                        base64::engine::general_purpose::STANDARD
                            .decode(data)
                            .map_err(|e| fail(format!("buffer {}: its base64 data: {e}", b.index())))?,
                    )
                } else {
                    Cow::Owned(
                        resource(&percent_decode(uri))
                            .map_err(|e| fail(format!("buffer {} ({uri}): {e}", b.index())))?,
                    )
                }
            }
        };
        if data.len() < b.length() {
            return Err(fail(format!(
                "buffer {} has {} bytes; the file says {}",
                b.index(),
                data.len(),
                b.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// A primitive's indices read as a slice, where they are packed 16- or 32-bit integers.
pub(super) fn packed_indices(prim: &::gltf::Primitive, buffers: &[Buffer]) -> Option<Vec<u32>> {
    let (b, kind) = packed(&prim.indices()?, buffers)?;
    match kind {
        ::gltf::accessor::DataType::U32 if cfg!(target_endian = "little") => Some(bytemuck::pod_collect_to_vec(b)),
        ::gltf::accessor::DataType::U32 => Some(
            b.chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
        ::gltf::accessor::DataType::U16 => Some(
            b.chunks_exact(2)
                .map(|c| u32::from(u16::from_le_bytes([c[0], c[1]])))
                .collect(),
        ),
        _ => None,
    }
}

/// An accessor's elements as one run of bytes, and their component type, where they are
/// tightly packed (no stride between them, nothing sparse) and lie inside their buffer: read
/// as a slice rather than element by element.
pub(super) fn packed<'b>(
    a: &::gltf::Accessor,
    buffers: &'b [Buffer],
) -> Option<(&'b [u8], ::gltf::accessor::DataType)> {
    let view = a.view()?;
    let size = a.size();
    if a.sparse().is_some() || a.normalized() || view.stride().is_some_and(|s| s != size) {
        return None;
    }
    let start = view.offset().checked_add(a.offset())?;
    let end = start.checked_add(a.count().checked_mul(size)?)?;
    if a.offset().checked_add(a.count().checked_mul(size)?)? > view.length() {
        return None;
    }
    let bytes = buffers.get(view.buffer().index())?.get(start..end)?;
    Some((bytes, a.data_type()))
}

/// The component types an attribute may have: the specification's, and KHR_mesh_quantization's
/// (read whether or not the file names the extension).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Components {
    /// Positions and texture coordinates: 32-bit floats, or 8- and 16-bit integers, signed or
    /// not, normalized or not.
    Any,
    /// Normals and tangents: 32-bit floats, or normalized signed 8- and 16-bit integers.
    Unit,
    /// Vertex colours: 32-bit floats, or normalized unsigned 8- and 16-bit integers (read as
    /// normalized where a file leaves the flag out, as the `gltf` crate's reader read them).
    Colour,
    /// Indices (checked by the caller).
    Index,
}

impl Components {
    fn allow(self, a: &::gltf::Accessor) -> bool {
        use ::gltf::accessor::DataType as T;
        match (self, a.data_type(), a.normalized()) {
            (Components::Index, ..) => true,
            // A normalized float is no type at all.
            (_, T::F32, normalized) => !normalized,
            (_, T::U32, _) => false,
            (Components::Any, ..) => true,
            (Components::Unit, T::I8 | T::I16, true) => true,
            (Components::Colour, T::U8 | T::U16, _) => true,
            _ => false,
        }
    }

    fn allowed(self) -> &'static str {
        match self {
            Components::Any => "32-bit floats or 8- and 16-bit integers",
            Components::Unit => "32-bit floats or normalized signed 8- and 16-bit integers",
            Components::Colour => "32-bit floats or normalized unsigned 8- and 16-bit integers",
            Components::Index => "unsigned integers",
        }
    }
}

/// Checks an accessor before it is read: its type, its component type (`components`), at
/// least one element, nothing sparse, and every element inside its buffer view and buffer.
pub(super) fn check_accessor(
    a: &::gltf::Accessor,
    buffers: &[Buffer],
    dims: &[::gltf::accessor::Dimensions],
    components: Components,
) -> Result<(), String> {
    if !dims.contains(&a.dimensions()) {
        return Err(format!("type {:?}, expected {:?}", a.dimensions(), dims[0]));
    }
    if !components.allow(a) {
        return Err(format!(
            "component type {:?}{}; phong reads {} here",
            a.data_type(),
            if a.normalized() { " (normalized)" } else { "" },
            components.allowed()
        ));
    }
    if a.count() == 0 {
        return Err("it has no elements".into());
    }
    if a.sparse().is_some() {
        return Err("sparse accessors are not read".into());
    }
    let Some(view) = a.view() else {
        return Err("it has no buffer view".into());
    };
    let size = a.size();
    let stride = view.stride().unwrap_or(size);
    // A stride shorter than an element would make the reader split elements (the crate then
    // panics: found by the `gltf` fuzz target).
    if stride < size {
        return Err(format!(
            "its buffer view's byteStride {stride} is shorter than an element ({size} bytes)"
        ));
    }
    let end = (a.count() as u64 - 1)
        .checked_mul(stride as u64)
        .and_then(|x| x.checked_add((a.offset() + size) as u64))
        .ok_or("its size overflows")?;
    if end > view.length() as u64 {
        return Err(format!("it ends at byte {end} of a {}-byte buffer view", view.length()));
    }
    let buffer_len = buffers.get(view.buffer().index()).map_or(0, |b| b.len()) as u64;
    if view.offset() as u64 + view.length() as u64 > buffer_len {
        return Err(format!(
            "its buffer view ends at byte {} of a {buffer_len}-byte buffer",
            view.offset() + view.length()
        ));
    }
    Ok(())
}

/// A checked accessor's elements as `N` floats each (its first `N` components), whatever its
/// component type: 32-bit floats as they are; integers, where normalized, mapped as the
/// specification says (unsigned `c / MAX`, signed `max(c / MAX, −1)`), else their values
/// (KHR_mesh_quantization; the node's transform or the texture transform scales them). `None`
/// where an element lies outside its buffer (not after [`check_accessor`]) or the type has
/// fewer than `N` components.
pub(super) fn floats<const N: usize>(a: &::gltf::Accessor, buffers: &[Buffer]) -> Option<Vec<[f32; N]>>
where
    [f32; N]: bytemuck::Pod,
{
    floats_as(a, buffers, a.normalized())
}

/// [`floats`], integers read as normalized where `normalized` (vertex colours, whatever their
/// flag says).
pub(super) fn floats_as<const N: usize>(
    a: &::gltf::Accessor,
    buffers: &[Buffer],
    normalized: bool,
) -> Option<Vec<[f32; N]>>
where
    [f32; N]: bytemuck::Pod,
{
    use ::gltf::accessor::DataType as T;
    // Packed floats of exactly `N` components (most files): the bytes are the values.
    if let Some((bytes, T::F32)) = packed(a, buffers)
        && cfg!(target_endian = "little")
        && a.dimensions().multiplicity() == N
    {
        return Some(bytemuck::pod_collect_to_vec(bytes));
    }
    let view = a.view()?;
    let (size, width) = (a.size(), a.data_type().size());
    if a.dimensions().multiplicity() < N {
        return None;
    }
    let stride = view.stride().unwrap_or(size);
    let bytes = buffers
        .get(view.buffer().index())?
        .get(view.offset().checked_add(a.offset())?..)?;
    let decode: fn(&[u8], bool) -> f32 = match a.data_type() {
        T::F32 => |c, _| f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
        // (Unsigned, times `1 / MAX`, as the `gltf` crate's reader made them: within an ulp
        // of `c / MAX`, and the images made before unchanged.)
        T::U8 => |c, n| {
            if n {
                f32::from(c[0]) * 255.0_f32.recip()
            } else {
                f32::from(c[0])
            }
        },
        T::U16 => |c, n| {
            let v = f32::from(u16::from_le_bytes([c[0], c[1]]));
            if n { v * 65535.0_f32.recip() } else { v }
        },
        T::I8 => |c, n| {
            let v = f32::from(c[0] as i8);
            if n { (v / 127.0).max(-1.0) } else { v }
        },
        T::I16 => |c, n| {
            let v = f32::from(i16::from_le_bytes([c[0], c[1]]));
            if n { (v / 32767.0).max(-1.0) } else { v }
        },
        T::U32 => return None,
    };
    (0..a.count())
        .map(|k| {
            let e = bytes.get(k.checked_mul(stride)?..)?.get(..size)?;
            Some(std::array::from_fn(|j| decode(&e[j * width..], normalized)))
        })
        .collect()
}

/// `%20` and the like decoded (glTF URIs are percent-encoded).
pub(super) fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%'
            && i + 2 < b.len()
            && let Ok(v) = u8::from_str_radix(std::str::from_utf8(&b[i + 1..i + 3]).unwrap_or("zz"), 16)
        {
            out.push(v);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}
