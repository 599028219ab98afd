//! One coordinator per store: an exclusive advisory lock (`flock` on Unix,
//! `LockFileEx` on Windows, through `std::fs::File::try_lock`) on a file
//! beside the store, `STORE.lock`, that records the holder's pid and host.
//!
//! The operating system drops the lock when its holder exits, even by
//! `kill -9`, so a crashed run never blocks `--resume`. The lock file is
//! left in place: deleting it would let two processes lock two different
//! files of one name. Readers (`status`, `export`) take no lock.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// Why the lock could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process holds the store.
    #[error(
        "{store}: in use by {holder} (lock {lock}); wait for that run to end, or choose another --store"
    )]
    Held {
        /// The store.
        store: PathBuf,
        /// The lock file.
        lock: PathBuf,
        /// Who holds it, as its lock file says (`pid 1234 on host lab-3`).
        holder: String,
    },
    /// The lock file could not be made, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The lock file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// Exclusive ownership of a store, released on drop.
#[derive(Debug)]
pub struct StoreLock {
    _file: File,
}

/// The lock file of a store: its name with `.lock` appended.
pub fn lock_path(store: &Path) -> PathBuf {
    let mut name = store.as_os_str().to_os_string();
    name.push(".lock");
    PathBuf::from(name)
}

/// The longest holder description read back from a lock file (bytes).
const MAX_HOLDER_BYTES: u64 = 256;

impl StoreLock {
    /// Takes the store's lock without waiting, or names who holds it.
    pub fn acquire(store: &Path) -> Result<StoreLock, LockError> {
        let path = lock_path(store);
        let io = |source| LockError::Io { path: path.clone(), source };
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let holder = read_holder(&mut file).map_err(io)?;
                return Err(LockError::Held { store: store.to_path_buf(), lock: path, holder });
            }
            Err(TryLockError::Error(source)) => return Err(io(source)),
        }
        write_holder(&mut file).map_err(io)?;
        Ok(StoreLock { _file: file })
    }
}

fn read_holder(file: &mut File) -> std::io::Result<String> {
    let mut text = String::new();
    file.take(MAX_HOLDER_BYTES).read_to_string(&mut text)?;
    let text = text.trim();
    Ok(if text.is_empty() {
        "another process (it has not written its name yet)".into()
    } else {
        text.into()
    })
}

fn write_holder(file: &mut File) -> std::io::Result<()> {
    let host = worker::run::host_name();
    file.set_len(0)?;
    file.rewind()?;
    writeln!(file, "pid {} on host {host}", std::process::id())?;
    file.sync_data()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_owner_is_refused_with_the_holders_pid_and_host() {
        let dir = tempfile::tempdir().unwrap();
        let store = dir.path().join("s.db");
        let first = StoreLock::acquire(&store).unwrap();
        let err = StoreLock::acquire(&store).unwrap_err().to_string();
        let holder = format!("pid {} on host {}", std::process::id(), worker::run::host_name());
        assert!(err.contains(&holder) && err.contains("s.db: in use by"), "{err}");
        drop(first);
        StoreLock::acquire(&store).expect("released on drop");
    }
}
