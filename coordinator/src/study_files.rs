//! Files a study names (`[model] spec`, `[model.excitation] file`): read
//! only from inside the study file's folder (after resolving symlinks),
//! only if regular (never a FIFO, a device such as `/dev/zero`, a socket
//! or a folder), and only up to [`MAX_STUDY_FILE_BYTES`]. Their text is
//! sent inline to workers, so it must also fit in one message.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest file a study may name (bytes): 16 MiB, a quarter of a message.
pub const MAX_STUDY_FILE_BYTES: u64 = 16 << 20;

/// Why a named file was refused (shown after `key = "value": `).
#[derive(Debug, thiserror::Error)]
pub enum StudyFileError {
    /// The path leaves the study's folder.
    #[error(
        "resolves to {resolved}, outside the study's folder {folder}; expected a file inside it"
    )]
    Outside {
        /// The resolved path.
        resolved: PathBuf,
        /// The study's folder.
        folder: PathBuf,
    },
    /// Not a regular file.
    #[error("{kind}, not a regular file; expected a regular file inside the study's folder")]
    NotRegular {
        /// What it is instead (`a FIFO`, `a character device`, ...).
        kind: &'static str,
    },
    /// Larger than the bound.
    #[error("{bytes} bytes; expected at most {MAX_STUDY_FILE_BYTES} bytes")]
    TooLarge {
        /// Its size (or the bytes read before giving up).
        bytes: u64,
    },
    /// Missing, unreadable or not UTF-8.
    #[error("cannot read it beside the study file ({0})")]
    Io(#[from] std::io::Error),
}

/// Reads `file`, relative to `folder`, under the rules of this module.
pub fn read_confined(folder: &Path, file: &str) -> Result<String, StudyFileError> {
    let folder = folder.canonicalize()?;
    let resolved = folder.join(file).canonicalize()?;
    if !resolved.starts_with(&folder) {
        return Err(StudyFileError::Outside { resolved, folder });
    }
    check_regular(&std::fs::metadata(&resolved)?)?;
    let f = File::open(&resolved)?;
    // Checked again on the opened file: it may have been swapped meanwhile.
    check_regular(&f.metadata()?)?;
    let mut text = String::new();
    f.take(MAX_STUDY_FILE_BYTES + 1).read_to_string(&mut text)?;
    if text.len() as u64 > MAX_STUDY_FILE_BYTES {
        return Err(StudyFileError::TooLarge { bytes: text.len() as u64 });
    }
    Ok(text)
}

fn check_regular(meta: &std::fs::Metadata) -> Result<(), StudyFileError> {
    if meta.is_file() {
        return if meta.len() > MAX_STUDY_FILE_BYTES {
            Err(StudyFileError::TooLarge { bytes: meta.len() })
        } else {
            Ok(())
        };
    }
    Err(StudyFileError::NotRegular { kind: kind(meta.file_type()) })
}

#[cfg(unix)]
fn kind(t: std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    match () {
        _ if t.is_dir() => "a folder",
        _ if t.is_fifo() => "a FIFO",
        _ if t.is_char_device() => "a character device",
        _ if t.is_block_device() => "a block device",
        _ if t.is_socket() => "a socket",
        _ => "a special file",
    }
}

#[cfg(not(unix))]
fn kind(t: std::fs::FileType) -> &'static str {
    if t.is_dir() {
        "a folder"
    } else {
        "a special file"
    }
}
