//! Loading a glTF's buffers, and the bounds checks that keep the accessor reader from slicing
//! past them (the `gltf` crate validates references, not lengths).

use super::ImportError;
use base64::Engine as _;
use gltf::buffer::Source;
use std::path::Path;

/// The bytes of every buffer, in buffer order: the GLB binary chunk, a `data:` URI (base64) or a
/// file next to the glTF. Each must hold at least the `byteLength` the glTF declares.
pub(super) fn load_buffers(
    document: &gltf::Document,
    blob: Option<Vec<u8>>,
    base_dir: Option<&Path>,
) -> Result<Vec<Vec<u8>>, ImportError> {
    let mut blob = blob;
    let mut out = Vec::new();
    for buffer in document.buffers() {
        let bad = |problem: String| ImportError::Buffer {
            index: buffer.index(),
            problem,
        };
        let data = match buffer.source() {
            Source::Bin => blob
                .take()
                .ok_or_else(|| bad("refers to the GLB binary chunk, which is missing".into()))?,
            Source::Uri(uri) => read_uri(uri, base_dir).map_err(bad)?,
        };
        if data.len() < buffer.length() {
            return Err(bad(format!(
                "holds {} bytes but declares byteLength {} (truncated?)",
                data.len(),
                buffer.length()
            )));
        }
        out.push(data);
    }
    Ok(out)
}

fn read_uri(uri: &str, base_dir: Option<&Path>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or("only base64 `data:` URIs are supported")?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("bad base64 in data URI: {e}"));
    }
    if uri.contains("://") {
        return Err(format!(
            "`{uri}`: only relative file paths and data URIs are supported"
        ));
    }
    let dir = base_dir.ok_or_else(|| {
        format!("`{uri}` is an external file, but the glTF was not read from a file")
    })?;
    let path = dir.join(percent_decode(uri));
    std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

/// URIs in glTF are percent-encoded (`my%20mesh.bin`).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(b)) => {
                out.push(b);
                i += 3;
            }
            (c, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Checks that every element `accessor` addresses lies inside its buffer view, and the view
/// inside its buffer (whose data length [`load_buffers`] checked).
pub(super) fn check_accessor(accessor: &gltf::Accessor) -> Result<(), String> {
    let which = format!("accessor {}", accessor.index());
    if accessor.sparse().is_some() {
        return Err(format!("{which}: sparse accessors are not supported"));
    }
    let view = accessor
        .view()
        .ok_or_else(|| format!("{which}: has no buffer view"))?;
    let buffer_end = view.offset().checked_add(view.length());
    if buffer_end.is_none_or(|end| end > view.buffer().length()) {
        return Err(format!(
            "{which}: buffer view {} runs past the end of buffer {}",
            view.index(),
            view.buffer().index()
        ));
    }
    let element = accessor.size();
    let stride = view.stride().unwrap_or(element).max(element);
    let needed = match accessor.count() {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(element))
            .and_then(|x| x.checked_add(accessor.offset())),
    };
    if needed.is_none_or(|needed| needed > view.length()) {
        return Err(format!(
            "{which}: {} elements run past the end of buffer view {}",
            accessor.count(),
            view.index()
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("a%zzb"), "a%zzb");
    }

    #[test]
    fn data_uris() {
        assert_eq!(
            read_uri("data:application/octet-stream;base64,AAEC", None).unwrap(),
            vec![0, 1, 2]
        );
        assert!(read_uri("data:text/plain,abc", None).is_err());
        assert!(read_uri("http://example.com/a.bin", None).is_err());
        assert!(read_uri("a.bin", None)
            .unwrap_err()
            .contains("not read from a file"));
    }
}
