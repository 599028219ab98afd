//! The files a bundle references (`bundle.toml`, its run files, `modal.csv`):
//! confined to the bundle's folder and regular files only, so a symbolic
//! link out of the folder, a FIFO (which would hang the read) or a device
//! such as `/dev/zero` (which never ends) is refused before it is opened.

use super::BundleError;
use std::fs::File;
use std::path::{Component, Path, PathBuf};

/// Resolves `rel` inside `dir`: refuses absolute paths, `..`, a missing
/// file, a symbolic link that leads out of `dir` and anything but a regular file.
pub(super) fn confined(dir: &Path, rel: &str) -> Result<PathBuf, String> {
    let path = Path::new(rel);
    if rel.is_empty()
        || path.is_absolute()
        || path.components().any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err("expected a path relative to the bundle directory, without \"..\"".into());
    }
    let full = dir.join(path);
    let Ok(meta) = std::fs::metadata(&full) else {
        return Err("no such file in the bundle".into());
    };
    // A symbolic link must not lead out of the bundle either.
    match (dir.canonicalize(), full.canonicalize()) {
        (Ok(root), Ok(target)) if target.starts_with(&root) => {}
        _ => return Err("resolves outside the bundle directory".into()),
    }
    if !meta.is_file() {
        return Err(NOT_REGULAR.into());
    }
    Ok(full)
}

/// Why a directory, FIFO, socket or device is refused.
const NOT_REGULAR: &str =
    "not a regular file (a directory, FIFO, socket or device): expected a plain file";

/// Opens `path` if it is a regular file of at most `max_bytes` bytes.
pub(super) fn open_regular(path: &Path, max_bytes: u64) -> Result<File, BundleError> {
    let io = |source| BundleError::Io { path: path.to_path_buf(), source };
    let file_err = |message: String| BundleError::File { path: path.to_path_buf(), message };
    // Checked before opening: opening a FIFO blocks until a writer comes.
    if !std::fs::metadata(path).map_err(io)?.is_file() {
        return Err(file_err(NOT_REGULAR.into()));
    }
    let file = File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(file_err(NOT_REGULAR.into()));
    }
    if meta.len() > max_bytes {
        return Err(file_err(format!("larger than the limit of {max_bytes} bytes")));
    }
    Ok(file)
}
