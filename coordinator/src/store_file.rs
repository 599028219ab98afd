//! The constant-time check made on a store file before SQLite opens it:
//! the SQLite header, and the file's length against the pages the header
//! describes (a truncated copy). The length check holds only when no
//! write-ahead log (`STORE-wal`) holds frames: SQLite reads the newest
//! pages, page 1 included, from the WAL, so after a checkpoint stopped by
//! a full disk the main file may be shorter than its own header says while
//! the store is whole (SQLite checks each WAL frame's checksum itself).

use crate::store::StoreError;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Size of the SQLite database header (bytes).
const DB_HEADER_BYTES: usize = 100;
/// Size of the WAL header (bytes), and of each frame's header.
const WAL_HEADER_BYTES: u64 = 32;
const WAL_FRAME_HEADER_BYTES: u64 = 24;
/// The two WAL magic numbers (big- and little-endian checksums).
const WAL_MAGIC: [u32; 2] = [0x377f_0682, 0x377f_0683];

/// The write-ahead log of a store: its name with `-wal` appended.
pub fn wal_path(store: &Path) -> PathBuf {
    let mut name = store.as_os_str().to_os_string();
    name.push("-wal");
    PathBuf::from(name)
}

/// Checks the SQLite header, and the length unless the WAL holds frames.
pub fn check_file(path: &Path) -> Result<(), StoreError> {
    let corrupt = |reason: String| StoreError::Corrupt { path: path.to_path_buf(), reason };
    let io = |source| StoreError::Io { path: path.to_path_buf(), source };
    let len = std::fs::metadata(path).map_err(io)?.len();
    if len < DB_HEADER_BYTES as u64 {
        return Err(corrupt(format!(
            "{len} bytes is too short for a SQLite database (truncated?)"
        )));
    }
    let mut header = [0u8; DB_HEADER_BYTES];
    std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut header)).map_err(io)?;
    if &header[..16] != b"SQLite format 3\0" {
        return Err(corrupt("not a SQLite database (bad header)".into()));
    }
    let page = match u16::from_be_bytes([header[16], header[17]]) {
        1 => 65536u64,
        p => p as u64,
    };
    if !(512..=65536).contains(&page) || !page.is_power_of_two() {
        return Err(corrupt(format!(
            "page size {page} in the header: expected a power of 2 from 512 to 65536"
        )));
    }
    if wal_has_frames(path, page)
        .map_err(|source| StoreError::Io { path: wal_path(path), source })?
    {
        return Ok(());
    }
    let pages = u32::from_be_bytes([header[28], header[29], header[30], header[31]]) as u64;
    if !len.is_multiple_of(page) || (pages > 0 && len < pages * page) {
        return Err(corrupt(format!(
            "file has {len} bytes but its header describes {pages} pages of {page} bytes (truncated)"
        )));
    }
    Ok(())
}

/// Whether the store's WAL exists with a valid header and at least one frame.
fn wal_has_frames(path: &Path, page: u64) -> std::io::Result<bool> {
    let wal = wal_path(path);
    let len = match std::fs::metadata(&wal) {
        Ok(m) => m.len(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(e),
    };
    if len < WAL_HEADER_BYTES + WAL_FRAME_HEADER_BYTES + page {
        return Ok(false);
    }
    let mut magic = [0u8; 4];
    std::fs::File::open(&wal)?.read_exact(&mut magic)?;
    Ok(WAL_MAGIC.contains(&u32::from_be_bytes(magic)))
}
