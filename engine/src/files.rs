//! Writing a file so that a reader, or a process killed at any moment, sees the old file or the
//! new one and never a part of either: the one atomic write of the workspace (the IBL disk
//! cache, goldens, reports).

use std::io::Write as _;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` atomically: into a temporary sibling (`.<name>.tmp<pid>.<n>`),
/// synced, then renamed over `path`. Creates the parent folder. Temporary siblings left by
/// processes that no longer run are removed first (best effort, Linux `/proc`).
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
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
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
