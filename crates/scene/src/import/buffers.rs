//! Loading a glTF's buffers, and the bounds checks that keep the accessor reader from slicing
//! past them (the `gltf` crate validates references, not lengths).

use super::ImportError;
use base64::Engine as _;
use gltf::buffer::Source;
use std::io::Read as _;
use std::path::{Component, Path, PathBuf};

/// The most bytes one import reads: the glTF or GLB file, and every buffer together.
pub const MAX_IMPORT_BYTES: u64 = 2 << 30;

/// The bytes of every buffer, in buffer order: the GLB binary chunk, a `data:` URI (base64) or a
/// file inside the glTF's folder ([`read_confined`]). Each must hold at least the `byteLength`
/// the glTF declares; only that many bytes are kept (or read, from a file).
pub(super) fn load_buffers(
    document: &gltf::Document,
    blob: Option<Vec<u8>>,
    base_dir: Option<&Path>,
) -> Result<Vec<Vec<u8>>, ImportError> {
    let mut blob = blob;
    let mut out = Vec::new();
    let mut budget = MAX_IMPORT_BYTES;
    for buffer in document.buffers() {
        let bad = |problem: String| ImportError::Buffer {
            index: buffer.index(),
            problem,
        };
        let length = buffer.length() as u64;
        budget = budget.checked_sub(length).ok_or_else(|| {
            bad(format!(
                "byteLength {length} takes the file past the {MAX_IMPORT_BYTES} bytes an import \
                 may read"
            ))
        })?;
        let mut data = match buffer.source() {
            Source::Bin => blob
                .take()
                .ok_or_else(|| bad("refers to the GLB binary chunk, which is missing".into()))?,
            Source::Uri(uri) => read_uri(uri, base_dir, ReadLimit::Exactly(length)).map_err(bad)?,
        };
        if (data.len() as u64) < length {
            return Err(bad(format!(
                "holds {} bytes but declares byteLength {} (truncated?)",
                data.len(),
                buffer.length()
            )));
        }
        data.truncate(buffer.length());
        out.push(data);
    }
    Ok(out)
}

/// The bytes `uri` names: a base64 `data:` URI, or a regular file inside `base_dir` read under
/// `limit`.
pub(super) fn read_uri(
    uri: &str,
    base_dir: Option<&Path>,
    limit: ReadLimit,
) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or("only base64 `data:` URIs are supported")?;
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("bad base64 in data URI: {e}"))?;
        return match limit {
            ReadLimit::AtMost(n) if bytes.len() as u64 > n => Err(format!(
                "the data URI holds {} bytes, more than the {n} an import may read",
                bytes.len()
            )),
            _ => Ok(bytes),
        };
    }
    if uri.contains("://") {
        return Err(format!(
            "`{uri}`: only relative file paths and data URIs are supported"
        ));
    }
    let dir = base_dir.ok_or_else(|| {
        format!("`{uri}` is an external file, but the glTF was not read from a file")
    })?;
    let path = confined_path(dir, &percent_decode(uri))?;
    read_regular_file(&path, limit)
}

/// `relative` inside `dir`, or why not. The policy for every file a glTF names (buffers now,
/// images when they are read): a relative path that, with `..` and symbolic links resolved,
/// stays inside the folder of the glTF. Absolute paths, drive or root prefixes and escapes are
/// refused, so a file from the internet cannot make histencil read `/etc/passwd`.
pub(super) fn confined_path(dir: &Path, relative: &str) -> Result<PathBuf, String> {
    let rel = Path::new(relative);
    if relative.is_empty() || relative.contains('\0') {
        return Err(format!("`{relative}` is not a file name"));
    }
    if rel.has_root() || rel.components().any(|c| matches!(c, Component::Prefix(_))) {
        return Err(format!(
            "`{relative}` is an absolute path; a glTF may only name files inside its own folder"
        ));
    }
    // A bare file name's folder (`Path::parent` of `scene.gltf` is ``) is the current one.
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let root = dir
        .canonicalize()
        .map_err(|e| format!("cannot resolve the glTF's folder {}: {e}", dir.display()))?;
    let joined = root.join(rel);
    let resolved = joined
        .canonicalize()
        .map_err(|e| format!("cannot read {}: {e}", joined.display()))?;
    if !resolved.starts_with(&root) {
        return Err(format!(
            "`{relative}` resolves to {}, outside the glTF's folder {}",
            resolved.display(),
            root.display()
        ));
    }
    Ok(resolved)
}

/// How much of a file [`read_regular_file`] takes.
#[derive(Clone, Copy, Debug)]
pub(super) enum ReadLimit {
    /// At least this many bytes must be there; only they are read.
    Exactly(u64),
    /// The whole file, which may not be larger.
    AtMost(u64),
}

/// Reads a regular file, bounded before reading: the file is opened without blocking (a FIFO
/// or a device would otherwise hang or never end), its type and size come from the open
/// handle's metadata (no race with a swap after a check), and no more than the limit is read.
pub(super) fn read_regular_file(path: &Path, limit: ReadLimit) -> Result<Vec<u8>, String> {
    let at = || path.display().to_string();
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options
        .open(path)
        .map_err(|e| format!("cannot read {}: {e}", at()))?;
    let meta = file
        .metadata()
        .map_err(|e| format!("cannot read {}: {e}", at()))?;
    if !meta.is_file() {
        return Err(format!(
            "{} is not a regular file (a directory, device, FIFO or socket)",
            at()
        ));
    }
    let size = meta.len();
    let take = match limit {
        ReadLimit::Exactly(n) if size < n => {
            return Err(format!(
                "{} holds {size} bytes but byteLength declares {n} (truncated?)",
                at()
            ))
        }
        ReadLimit::Exactly(n) => n,
        ReadLimit::AtMost(n) if size > n => {
            return Err(format!(
                "{} is {size} bytes, more than the {n} an import may read",
                at()
            ))
        }
        ReadLimit::AtMost(_) => size,
    };
    let mut data = Vec::with_capacity(take as usize);
    file.take(take)
        .read_to_end(&mut data)
        .map_err(|e| format!("cannot read {}: {e}", at()))?;
    if (data.len() as u64) < take {
        return Err(format!("{} shrank while it was read", at()));
    }
    Ok(data)
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
/// inside its buffer (whose data length [`load_buffers`] checked). A sparse accessor's base
/// view is optional (zeros without one); its indices and values must lie inside their views,
/// and its indices must rise strictly and stay below the accessor's count, as glTF requires
/// (the reader would otherwise skip or misplace substitutions silently).
pub(super) fn check_accessor(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<(), String> {
    let which = format!("accessor {}", accessor.index());
    let element = accessor.size();
    if accessor.count() == 0 {
        return Err(format!("{which}: count must be at least 1"));
    }
    match accessor.view() {
        Some(view) => check_elements(&which, &view, accessor.offset(), accessor.count(), element)?,
        None if accessor.sparse().is_some() => {}
        None => return Err(format!("{which}: has no buffer view")),
    }
    let Some(sparse) = accessor.sparse() else {
        return Ok(());
    };
    let count = sparse.count();
    if count == 0 || count > accessor.count() {
        return Err(format!(
            "{which}: sparse count {count} must be 1 to the accessor's count {}",
            accessor.count()
        ));
    }
    let indices = sparse.indices();
    let index_size = indices.index_type().size();
    let which_indices = format!("{which} sparse indices");
    check_elements(
        &which_indices,
        &indices.view(),
        indices.offset(),
        count,
        index_size,
    )?;
    let values = sparse.values();
    let which_values = format!("{which} sparse values");
    check_elements(
        &which_values,
        &values.view(),
        values.offset(),
        count,
        element,
    )?;
    let view = indices.view();
    let data = &buffers[view.buffer().index()];
    let stride = view.stride().unwrap_or(index_size).max(index_size);
    let mut previous: Option<u64> = None;
    for k in 0..count {
        let at = view.offset() + indices.offset() + k * stride;
        let bytes = &data[at..at + index_size];
        let index = bytes
            .iter()
            .rev()
            .fold(0u64, |v, b| (v << 8) | u64::from(*b));
        if previous.is_some_and(|p| index <= p) || index >= accessor.count() as u64 {
            return Err(format!(
                "{which_indices}: index {index} (entry {k}) must rise strictly and stay below \
                 the count {}",
                accessor.count()
            ));
        }
        previous = Some(index);
    }
    Ok(())
}

/// `count` elements of `element` bytes from `offset` in `view` lie inside the view, and the
/// view inside its buffer.
fn check_elements(
    which: &str,
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    element: usize,
) -> Result<(), String> {
    let buffer_end = view.offset().checked_add(view.length());
    if buffer_end.is_none_or(|end| end > view.buffer().length()) {
        return Err(format!(
            "{which}: buffer view {} runs past the end of buffer {}",
            view.index(),
            view.buffer().index()
        ));
    }
    // Elements may not overlap: the gltf crate's accessor iterator asserts this (found by
    // fuzzing), and a smaller stride is no valid layout.
    if let Some(stride) = view.stride().filter(|s| *s < element) {
        return Err(format!(
            "{which}: buffer view {} has byteStride {stride}, less than its {element}-byte \
             elements",
            view.index()
        ));
    }
    let stride = view.stride().unwrap_or(element);
    let needed = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(element))
            .and_then(|x| x.checked_add(offset)),
    };
    if needed.is_none_or(|needed| needed > view.length()) {
        return Err(format!(
            "{which}: {count} elements run past the end of buffer view {}",
            view.index()
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bare_file_names_folder_is_the_current_one() {
        // Tests run in the crate's folder.
        let here = Path::new("Cargo.toml").canonicalize().unwrap();
        assert_eq!(confined_path(Path::new(""), "Cargo.toml"), Ok(here));
        let outside = confined_path(Path::new(""), "../../Cargo.toml").unwrap_err();
        assert!(outside.contains("outside the glTF's folder"), "{outside}");
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("a%zzb"), "a%zzb");
    }

    #[test]
    fn data_uris() {
        assert_eq!(
            read_uri(
                "data:application/octet-stream;base64,AAEC",
                None,
                ReadLimit::Exactly(3)
            )
            .unwrap(),
            vec![0, 1, 2]
        );
        assert!(read_uri("data:text/plain,abc", None, ReadLimit::Exactly(3)).is_err());
        assert!(read_uri("data:a;base64,AAEC", None, ReadLimit::AtMost(2))
            .unwrap_err()
            .contains("more than the 2"));
        assert!(read_uri("http://example.com/a.bin", None, ReadLimit::Exactly(3)).is_err());
        assert!(read_uri("a.bin", None, ReadLimit::Exactly(3))
            .unwrap_err()
            .contains("not read from a file"));
    }

    /// A folder holding `scene/` with a 16-byte `ok.bin`, next to an `outside.bin`.
    fn sandbox(tag: &str) -> PathBuf {
        let root =
            std::env::temp_dir().join(format!("histencil-confine-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("scene/sub")).unwrap();
        std::fs::write(root.join("scene/ok.bin"), [7u8; 16]).unwrap();
        std::fs::write(root.join("scene/sub/deep.bin"), [7u8; 16]).unwrap();
        std::fs::write(root.join("outside.bin"), [1u8; 4096]).unwrap();
        root
    }

    /// Every way a URI can leave the folder or name something that is not a plain file is
    /// refused quickly (a FIFO or /dev/zero would hang or never end), and files inside are read
    /// to exactly `byteLength`.
    #[cfg(unix)]
    #[test]
    fn only_regular_files_inside_the_folder_are_read_and_only_byte_length_of_them() {
        use std::os::unix::fs::symlink;
        let root = sandbox("policy");
        let dir = root.join("scene");
        symlink(root.join("outside.bin"), dir.join("link-out.bin")).unwrap();
        symlink(dir.join("ok.bin"), dir.join("link-in.bin")).unwrap();
        symlink("/dev/zero", dir.join("zero.bin")).unwrap();
        symlink("/etc", dir.join("etc")).unwrap();
        let fifo = std::ffi::CString::new(dir.join("fifo.bin").to_str().unwrap()).unwrap();
        // SAFETY: `fifo` is a NUL-terminated path (`CString`) that outlives the call.
        assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
        let refused = [
            ("/etc/passwd", "absolute"),
            ("%2Fetc%2Fpasswd", "absolute"),
            ("../outside.bin", "outside the glTF's folder"),
            ("sub/../../outside.bin", "outside the glTF's folder"),
            ("%2E%2E/outside.bin", "outside the glTF's folder"),
            ("link-out.bin", "outside the glTF's folder"),
            ("zero.bin", "outside the glTF's folder"),
            ("etc/passwd", "outside the glTF's folder"),
            ("fifo.bin", "not a regular file"),
            ("sub", "not a regular file"),
            (".", "not a regular file"),
            ("missing.bin", "cannot read"),
            ("", "not a file name"),
            ("ok.bin%00x", "not a file name"),
        ];
        for (uri, why) in refused {
            let start = std::time::Instant::now();
            let err = read_uri(uri, Some(&dir), ReadLimit::Exactly(4)).unwrap_err();
            assert!(err.contains(why), "`{uri}`: {err}");
            assert!(
                start.elapsed().as_secs() < 5,
                "`{uri}` took {:?}",
                start.elapsed()
            );
        }
        for uri in [
            "ok.bin",
            "link-in.bin",
            "sub/deep.bin",
            "sub/../ok.bin",
            "ok%2Ebin",
        ] {
            assert_eq!(
                read_uri(uri, Some(&dir), ReadLimit::Exactly(4)).unwrap(),
                vec![7; 4],
                "{uri}"
            );
        }
        let err = read_uri("ok.bin", Some(&dir), ReadLimit::Exactly(17)).unwrap_err();
        assert!(
            err.contains("holds 16 bytes but byteLength declares 17"),
            "{err}"
        );
        let err = read_regular_file(&dir.join("ok.bin"), ReadLimit::AtMost(15)).unwrap_err();
        assert!(err.contains("more than the 15"), "{err}");
        let err = read_regular_file(&dir.join("fifo.bin"), ReadLimit::AtMost(15)).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
        let _ = std::fs::remove_dir_all(&root);
    }
}
