//! Atomic output: every file swarmmap writes goes to a temporary file in the target's
//! directory and is renamed over the target only once it is complete, so an interrupted
//! run (Ctrl-C, a crash, a full disk) never leaves a torn file behind. The temporary file
//! is created with the mode an ordinary `File::create` uses (0666, reduced by the process
//! umask: 0644 under the usual 022), not the owner-only 0600 of `tempfile`'s default, so
//! outputs are readable like any other file the user writes.

use std::fs;
use std::io::{self, Write};
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file in the same directory, fsync, rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Streams into `path` atomically: `fill` writes the content into a buffered temporary
/// file, which replaces `path` only if `fill` succeeds.
pub fn write_atomic_with<F>(path: &Path, fill: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    fs::create_dir_all(dir)?;
    let mut builder = tempfile::Builder::new();
    builder.prefix(".swarmmap-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Subject to the umask, exactly as `File::create`.
        builder.permissions(fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    {
        let mut w = io::BufWriter::new(tmp.as_file_mut());
        fill(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_only_on_success() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        write_atomic(&p, b"first").unwrap();
        let err = write_atomic_with(&p, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("interrupted"))
        });
        assert!(err.is_err());
        assert_eq!(fs::read(&p).unwrap(), b"first");
        // No temporary file is left behind.
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    /// The process umask, from `/proc/self/status` (Linux ≥ 4.7), read without changing it.
    #[cfg(target_os = "linux")]
    fn umask() -> Option<u32> {
        let status = fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("Umask:"))?;
        u32::from_str_radix(line.trim_start_matches("Umask:").trim(), 8).ok()
    }

    #[cfg(unix)]
    #[test]
    fn outputs_get_the_mode_of_an_ordinary_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let atomic = dir.path().join("atomic.csv");
        let plain = dir.path().join("plain.csv");
        write_atomic(&atomic, b"a,b\n").unwrap();
        // Oracle: what `File::create` gives under the same umask.
        fs::write(&plain, b"a,b\n").unwrap();
        let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&atomic), mode(&plain));
        #[cfg(target_os = "linux")]
        if let Some(mask) = umask() {
            assert_eq!(mode(&atomic), 0o666 & !mask);
            if mask == 0o022 {
                assert_eq!(mode(&atomic), 0o644);
            }
        }
        // Replacing an existing file keeps the ordinary mode too.
        write_atomic(&atomic, b"c,d\n").unwrap();
        assert_eq!(mode(&atomic), mode(&plain));
        assert_eq!(fs::read(&atomic).unwrap(), b"c,d\n");
    }
}
