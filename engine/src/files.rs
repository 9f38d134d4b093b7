//! Writing a file so that a reader, or a process killed at any moment, sees the old file or the
//! new one and never a part of either: the one atomic write of the workspace (the IBL disk
//! cache, goldens, reports).

use std::io::Write as _;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` atomically: into a temporary sibling (`.<name>.tmp<pid>.<n>`),
/// synced, then renamed over `path`. Creates the parent folder. Temporary siblings left by
/// processes that no longer run are removed first (best effort, Linux `/proc`).
///
/// A `path` that is a symbolic link to a file has that file replaced (the link stays); one
/// that is not a regular file (`/dev/stdout`, a pipe, a device) is written through, not
/// replaced, and its errors are returned (`/dev/full`: no space left).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomically_with(path, bytes, || {})
}

/// [`write_atomically`], calling `before_rename` once the temporary file is written and synced
/// (tests hold the write there to kill the process mid-write).
pub fn write_atomically_with(
    path: &Path,
    bytes: &[u8],
    before_rename: impl FnOnce(),
) -> std::io::Result<()> {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    match std::fs::metadata(path) {
        // A device, a pipe, a socket: written through (renaming over it would replace it).
        Ok(meta) if !meta.is_file() && !meta.is_dir() => return write_through(path, bytes),
        // A link to a file: the file is replaced, the link kept.
        Ok(meta) if meta.is_file() && is_link => {
            let target = std::fs::canonicalize(path)?;
            return write_atomically_with(&target, bytes, before_rename);
        }
        // A dangling link: writing through it creates its target.
        Err(_) if is_link => return write_through(path, bytes),
        _ => {}
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| {
            if dir.exists() && !dir.is_dir() {
                std::io::Error::new(
                    std::io::ErrorKind::NotADirectory,
                    format!("{} is not a folder", dir.display()),
                )
            } else {
                e
            }
        })?;
    }
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    remove_stale_temporaries(path, &file_name);
    // Unique per process and call: threads writing the same file never share a temporary.
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let temporary = path.with_file_name(format!(
        ".{file_name}.tmp{}.{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let result = (|| {
        let mut file = std::fs::File::create(&temporary)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        before_rename();
        std::fs::rename(&temporary, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

/// Writes `bytes` into what `path` is (a device, a pipe, a link's target), flushed.
fn write_through(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)?;
    file.write_all(bytes)?;
    file.flush()
}

/// Removes `.<file_name>.tmp<pid>.<n>` siblings of `path` whose process is gone (Linux: no
/// `/proc/<pid>`); best effort.
fn remove_stale_temporaries(path: &Path, file_name: &str) {
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let prefix = format!(".{file_name}.tmp");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(pid) = name
            .strip_prefix(&prefix)
            .and_then(|rest| rest.split('.').next())
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/file.bin");
        write_atomically(&path, b"old").unwrap();
        write_atomically(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        let names: Vec<_> = std::fs::read_dir(path.parent().unwrap())
            .unwrap()
            .flatten()
            .map(|e| e.file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("file.bin")]);
    }

    #[test]
    fn a_link_keeps_pointing_at_its_replaced_file_and_a_device_is_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("real.xml");
        std::fs::write(&file, b"old").unwrap();
        let link = dir.path().join("link.xml");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        write_atomically(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&file).unwrap(), b"new");
        // A full device reports its error, and is still a device afterwards.
        let full = Path::new("/dev/full");
        if full.exists() {
            let error = write_atomically(full, b"x").unwrap_err();
            assert_eq!(error.raw_os_error(), Some(28), "{error}");
            assert!(!std::fs::metadata(full).unwrap().is_file());
        }
        // A parent that is a file is named.
        let error = write_atomically(&file.join("inner.png"), b"x").unwrap_err();
        assert!(error.to_string().contains("is not a folder"), "{error}");
    }

    #[test]
    fn a_dead_process_temporary_is_removed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("file.bin");
        // No process has pid 4294967294 (above Linux's pid_max).
        let stale = dir.path().join(".file.bin.tmp4294967294.0");
        std::fs::write(&stale, b"part").unwrap();
        write_atomically(&path, b"whole").unwrap();
        assert!(!stale.exists());
    }
}
