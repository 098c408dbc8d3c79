//! Atomic output: every file swarmmap writes goes to a temporary file in the target's
//! directory and is renamed over the target only once it is complete, so an interrupted
//! run (Ctrl-C, a crash, a full disk) never leaves a torn file behind. The temporary file
//! is created with the mode an ordinary `File::create` uses (0666, reduced by the process
//! umask: 0644 under the usual 022), not the owner-only 0600 of `tempfile`'s default, so
//! outputs are readable like any other file the user writes.
//!
//! Interrupts: a signal kills the process between any two instructions, possibly while a
//! temporary file is half written. [`install_interrupt_handler`] (called by the command
//! line) catches Ctrl-C (SIGINT, SIGTERM, SIGHUP), removes the temporary files still in
//! flight (every target keeps its previous content or is absent) and exits with status
//! 130, so an interrupted run leaves only whole files behind, and no debris. A hang-up the
//! process started to ignore (SIGHUP under `nohup`) stays ignored.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

/// Temporary files being written, removed by the interrupt handler.
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn in_flight() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    IN_FLIGHT.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Exit status of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
pub const INTERRUPTED_STATUS: i32 = 130;

/// Installs the process-wide Ctrl-C handler described in the module docs. Call it once,
/// from a binary; a second call returns an error.
pub fn install_interrupt_handler() -> Result<(), ctrlc::Error> {
    // A hang-up the process was started to ignore (`nohup`) stays ignored: the handler
    // would override it. (SIGINT, which a shell script's background jobs start ignoring,
    // is still caught: only an explicit `kill -INT` reaches them, and it means stop.)
    #[cfg(unix)]
    let ignored: Vec<libc::c_int> = [libc::SIGHUP]
        .into_iter()
        .filter(|&s| is_ignored(s))
        .collect();
    ctrlc::set_handler(|| {
        // Held until exit: no write may register (or rename) a file after the sweep.
        let files = in_flight();
        for f in files.iter() {
            let _ = fs::remove_file(f);
        }
        // Not `eprintln!`, which panics when stderr is gone (the terminal that hung up):
        // the handler must reach the exit.
        let _ = writeln!(
            io::stderr(),
            "interrupted: files already written are complete; partial ones were removed"
        );
        std::process::exit(INTERRUPTED_STATUS);
    })?;
    #[cfg(unix)]
    for s in ignored {
        // SAFETY: `signal` with `SIG_IGN` installs no handler code; it restores the
        // disposition the process was started with.
        unsafe {
            libc::signal(s, libc::SIG_IGN);
        }
    }
    Ok(())
}

/// Whether the process was started with signal `s` ignored.
#[cfg(unix)]
fn is_ignored(s: libc::c_int) -> bool {
    // SAFETY: `sigaction` with a null new action only reads the current one into `old`,
    // a zeroed plain-data struct it fully owns.
    unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        libc::sigaction(s, std::ptr::null(), &mut old) == 0 && old.sa_sigaction == libc::SIG_IGN
    }
}

/// A JSON error of the file at `path` as `FILE:LINE:COL` and what is wrong there
/// (`serde_json` writes the place in prose at the end: "… at line 1 column 110").
pub fn json_error_at(path: &Path, e: &serde_json::Error) -> (String, String) {
    let text = e.to_string();
    let what = match text.rsplit_once(" at line ") {
        Some((what, _)) if e.line() > 0 => what.to_string(),
        _ => text,
    };
    let place = if e.line() > 0 {
        format!("{}:{}:{}", path.display(), e.line(), e.column())
    } else {
        path.display().to_string()
    };
    (place, what)
}

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
    // Created and registered under the lock: the interrupt handler holds it from its sweep
    // until exit, so no temporary file can appear after the sweep.
    let (mut tmp, tmp_path) = {
        let mut files = in_flight();
        let tmp = builder.tempfile_in(dir)?;
        let tmp_path = tmp.path().to_path_buf();
        files.push(tmp_path.clone());
        (tmp, tmp_path)
    };
    let result = (|| {
        {
            let mut w = io::BufWriter::new(tmp.as_file_mut());
            fill(&mut w)?;
            w.flush()?;
        }
        tmp.as_file().sync_all()?;
        // Renamed under the lock, so the interrupt handler sees either the temporary file
        // (and removes it) or the finished target, never a half-done rename.
        let mut files = in_flight();
        files.retain(|f| f != &tmp_path);
        tmp.persist(path).map(|_| ()).map_err(|e| e.error)
    })();
    if result.is_err() {
        in_flight().retain(|f| f != &tmp_path);
    }
    result
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

/// Removes the files of `dir` that an earlier run wrote and this one did not: those whose
/// name `ours` recognises as swarmmap's and that are not in `written`. Mapping a log again
/// with fewer windows (`swarmmap map --windows`) would otherwise leave the old windows'
/// files beside the new ones, to be read as theirs. Nothing else is touched; a missing
/// `dir` is nothing to do.
pub fn remove_stale(
    dir: &Path,
    written: &std::collections::BTreeSet<String>,
    ours: impl Fn(&str) -> bool,
) -> io::Result<()> {
    let entries = match fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    for entry in entries {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().to_string();
        if ours(&name) && !written.contains(&name) && entry.file_type()?.is_file() {
            fs::remove_file(entry.path())?;
        }
    }
    Ok(())
}

/// Whether `name` is one of `maps/`'s per-window or per-connection files
/// (`window_<i>.json`, `connection_<i>.json`), for [`remove_stale`].
pub fn is_numbered_map(name: &str) -> bool {
    numbered(name, |rest| rest == ".json")
}

/// Whether `name` is one of `report/`'s per-window or per-connection figures
/// (`window_<i>_<kind>.svg`, `connection_<i>_<kind>.svg`), for [`remove_stale`].
pub fn is_numbered_figure(name: &str) -> bool {
    numbered(name, |rest| rest.starts_with('_') && rest.ends_with(".svg"))
}

/// Whether `name` is `window_<N><rest>` or `connection_<N><rest>` for a number `N` and a
/// `rest` that `tail` accepts.
fn numbered(name: &str, tail: impl Fn(&str) -> bool) -> bool {
    ["window", "connection"].iter().any(|p| {
        name.strip_prefix(p)
            .and_then(|r| r.strip_prefix('_'))
            .is_some_and(|r| {
                let digits = r.chars().take_while(char::is_ascii_digit).count();
                digits > 0 && tail(&r[digits..])
            })
    })
}

#[cfg(test)]
mod stale_tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn only_unwritten_numbered_outputs_are_removed() {
        let tmp = tempfile::tempdir().unwrap();
        let names = [
            "window_1.json",
            "window_2.json",
            "window_12.json",
            "connection_3.json",
            "connections.json",
            "global.json",
            "window_x.json",
            "notes.txt",
        ];
        for n in names {
            fs::write(tmp.path().join(n), "x").unwrap();
        }
        let written: BTreeSet<String> = ["window_1.json", "connections.json"]
            .into_iter()
            .map(String::from)
            .collect();
        remove_stale(tmp.path(), &written, is_numbered_map).unwrap();
        let mut left: Vec<String> = fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        left.sort();
        assert_eq!(
            left,
            [
                "connections.json",
                "global.json",
                "notes.txt",
                "window_1.json",
                "window_x.json"
            ]
        );
        assert!(is_numbered_figure("window_3_diagram.svg"));
        assert!(is_numbered_figure("connection_12_cloud.svg"));
        assert!(!is_numbered_figure("window_3.json") && !is_numbered_figure("global.svg"));
        // A directory that does not exist is nothing to clean.
        remove_stale(&tmp.path().join("none"), &written, |_| true).unwrap();
    }
}
