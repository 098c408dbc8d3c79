//! Ctrl-C never leaves a torn file (issue #5 §2): `swarmmap run` is interrupted with
//! SIGINT at a sweep of moments, from start-up to completion, and after each interrupt
//! every file in the output directory must be byte-identical to the same file of an
//! uninterrupted run with the same seed (files with wall-clock timings must parse whole),
//! and no temporary file may remain.

#![cfg(unix)]

use std::collections::BTreeMap;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

const WORLD: &str = "tests/fixtures/worlds/tiny.ron";
/// Files whose content includes wall-clock timings: compared by parsing, not by bytes.
const TIMED: [&str; 2] = ["meta.json", "summary.json"];
/// The report page shows the timings too: it must be whole (end with its closing tag).
const PAGE: &str = "index.html";

fn run(out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_swarmmap"));
    c.args(["run", WORLD, "--quiet", "--trajectories", "0.05", "--out"])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    c
}

/// Every file under `dir`, by path relative to `dir`.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_path_buf();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

#[test]
fn interrupting_a_run_leaves_only_whole_files() {
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    let t0 = Instant::now();
    assert!(run(&reference).status().unwrap().success());
    let full = t0.elapsed();
    let expected = files(&reference);
    assert!(
        expected.len() >= 8,
        "reference run wrote {:?}",
        expected.keys()
    );

    // Interrupt at 24 moments spread over (and a little beyond) a whole run.
    let (mut interrupted, mut finished, mut partial) = (0, 0, 0);
    for k in 0..24u32 {
        let out = tmp.path().join(format!("run{k}"));
        let mut child = run(&out).spawn().unwrap();
        std::thread::sleep(full.mul_f64(f64::from(k) / 20.0));
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        let status = child.wait().unwrap();
        match (status.code(), status.signal()) {
            (Some(0), _) => finished += 1,
            // 130: our handler; SIGINT itself: before the handler was installed.
            (Some(130), _) | (None, Some(2)) => interrupted += 1,
            other => panic!("interrupt {k}: unexpected exit {other:?}"),
        }
        let written = files(&out);
        if status.code() != Some(0) && !written.is_empty() {
            partial += 1;
        }
        for (rel, bytes) in written {
            let name = rel.file_name().unwrap().to_string_lossy().to_string();
            assert!(
                !name.ends_with(".tmp"),
                "interrupt {k}: temporary file {rel:?} left behind"
            );
            let want = expected
                .get(&rel)
                .unwrap_or_else(|| panic!("interrupt {k}: unexpected file {rel:?}"));
            if name == PAGE {
                let text = String::from_utf8(bytes).unwrap();
                assert!(
                    text.trim_end().ends_with("</html>"),
                    "interrupt {k}: {rel:?} is torn"
                );
            } else if TIMED.contains(&name.as_str()) {
                serde_json::from_slice::<serde_json::Value>(&bytes)
                    .unwrap_or_else(|e| panic!("interrupt {k}: {rel:?} is torn: {e}"));
            } else {
                assert!(&bytes == want, "interrupt {k}: {rel:?} differs (torn)");
            }
        }
    }
    // The sweep must have caught runs in the act, not only before or after.
    assert!(interrupted > 0, "no run was interrupted");
    assert!(finished + interrupted == 24);
    eprintln!(
        "{interrupted} interrupted ({partial} with some outputs written), {finished} finished"
    );
}

/// `swarmmap run` of seed `seed` into `out`.
fn run_seed(out: &Path, seed: &str) -> Command {
    let mut c = run(out);
    c.args(["--seed", seed]);
    c
}

fn copy_dir(from: &Path, to: &Path) {
    for (rel, bytes) in files(from) {
        let path = to.join(rel);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
}

/// The seed a whole `meta.json` or `summary.json` records.
fn seed_of(bytes: &[u8]) -> Option<u64> {
    serde_json::from_slice::<serde_json::Value>(bytes).ok()?["seed"].as_u64()
}

#[test]
fn interrupting_a_run_over_an_earlier_one_never_mixes_the_two() {
    // Found by an adversarial pass (thirty-seventh session): a run into a directory that
    // held another run, interrupted while writing, left the new encounters beside the old
    // meta.json and trajectories, and `swarmmap map` then judged them by the wrong world.
    let tmp = tempfile::tempdir().unwrap();
    let old = tmp.path().join("old");
    assert!(run_seed(&old, "1").status().unwrap().success());
    let new = tmp.path().join("new");
    let t0 = Instant::now();
    assert!(run_seed(&new, "2").status().unwrap().success());
    let full = t0.elapsed();
    let (old_files, new_files) = (files(&old), files(&new));
    assert_ne!(
        old_files.get(Path::new("encounters.csv")),
        new_files.get(Path::new("encounters.csv"))
    );

    // Interrupt from early in the run to past its end.
    let (mut untouched, mut old_part, mut new_part) = (0, 0, 0);
    for k in 0..20u32 {
        let out = tmp.path().join(format!("over{k}"));
        copy_dir(&old, &out);
        let mut child = run_seed(&out, "2").spawn().unwrap();
        std::thread::sleep(full.mul_f64(0.1 + f64::from(k) / 20.0));
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        child.wait().unwrap();
        let got = files(&out);
        if got == old_files {
            // Interrupted before the new run touched anything: the old run stands whole.
            untouched += 1;
            continue;
        }
        // Each file left is the old run's or the new run's (or both, where the two runs
        // write the same bytes); never old ones beside new ones.
        let summary_seed = got.get(Path::new("summary.json")).and_then(|b| seed_of(b));
        let (mut only_old, mut only_new) = (Vec::new(), Vec::new());
        for (rel, bytes) in &got {
            let name = rel.file_name().unwrap().to_string_lossy().to_string();
            assert!(
                !name.ends_with(".tmp"),
                "interrupt {k}: {rel:?} left behind"
            );
            let of = |files: &BTreeMap<PathBuf, Vec<u8>>, seed: u64| {
                files.contains_key(rel)
                    && if TIMED.contains(&name.as_str()) {
                        seed_of(bytes) == Some(seed)
                    } else if name == PAGE {
                        // The page shows timings: it is the run of the summary beside it,
                        // which the page is never left without.
                        summary_seed == Some(seed)
                    } else {
                        files[rel] == *bytes
                    }
            };
            match (of(&old_files, 1), of(&new_files, 2)) {
                (true, false) => only_old.push(rel.clone()),
                (false, true) => only_new.push(rel.clone()),
                (true, true) => {}
                (false, false) => panic!("interrupt {k}: {rel:?} is neither run's (torn?)"),
            }
        }
        assert!(
            only_old.is_empty() || only_new.is_empty(),
            "interrupt {k}: the old run's {only_old:?} beside the new run's {only_new:?}"
        );
        if only_new.is_empty() {
            old_part += 1;
        } else {
            new_part += 1;
        }
    }
    eprintln!(
        "{untouched} left the old run whole, {old_part} part of it, {new_part} held the new run's files"
    );
    // The sweep must catch the new run's files being written, not only the old run.
    assert!(
        new_part > 0,
        "no interrupt came after the new run began writing"
    );
}

#[test]
fn sigterm_and_sighup_are_handled_like_ctrl_c() {
    // Found by the fortieth session's review: only SIGINT was caught (the `termination`
    // feature of `ctrlc` was off), so SIGTERM and SIGHUP killed the process outright, with
    // status 143 or 129, no message and any temporary file left behind.
    let tmp = tempfile::tempdir().unwrap();
    for signal in ["TERM", "HUP"] {
        let out = tmp.path().join(signal);
        // A run that takes seconds: the signal lands after start-up, mid-simulation.
        let mut command = Command::new(env!("CARGO_BIN_EXE_swarmmap"));
        command
            .args(["simulate", "worlds/scenario2.ron", "--quiet", "--out"])
            .arg(&out)
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        hang_up_as_by_default(&mut command);
        let child = command.spawn().unwrap();
        std::thread::sleep(std::time::Duration::from_millis(800));
        kill(signal, child.id());
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(
            (output.status.code(), output.status.signal()),
            (Some(130), None),
            "SIG{signal}: {stderr}"
        );
        assert!(stderr.contains("interrupted"), "SIG{signal}: {stderr}");
        for rel in files(&out).keys() {
            assert!(
                !rel.to_string_lossy().ends_with(".tmp"),
                "SIG{signal}: {rel:?} left behind"
            );
        }
    }
}

#[test]
fn a_run_started_under_nohup_ignores_the_hang_up() {
    // Found by the fortieth session's review: with SIGHUP caught, `nohup swarmmap ...` lost
    // its protection (the handler replaced the ignored disposition and stopped the run).
    if Command::new("nohup").arg("true").status().is_err() {
        eprintln!("no `nohup` on this machine: skipped");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let mut child = Command::new("nohup")
        .arg(env!("CARGO_BIN_EXE_swarmmap"))
        .args(["simulate", "worlds/scenario2.ron", "--quiet", "--out"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(800));
    kill("HUP", child.id());
    std::thread::sleep(std::time::Duration::from_millis(300));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the run stopped on a hang-up it was started to ignore"
    );
    kill("TERM", child.id());
    assert_eq!(child.wait().unwrap().code(), Some(130));
}

/// Starts `command` with SIGHUP's default disposition. A run started with SIGHUP ignored
/// keeps it ignored ([`a_run_started_under_nohup_ignores_the_hang_up`]), and a child
/// inherits an ignored disposition: without this, the tests that expect a hang-up to stop
/// the run failed whenever the suite itself ran under `nohup` (forty-fourth session: `nohup
/// ./.ci/run`).
fn hang_up_as_by_default(command: &mut Command) {
    // SAFETY: `signal` is async-signal-safe, so it may run between fork and exec.
    unsafe {
        command.pre_exec(|| {
            if libc::signal(libc::SIGHUP, libc::SIG_DFL) == libc::SIG_ERR {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

/// Sends SIG`signal` to process `pid`.
fn kill(signal: &str, pid: u32) {
    let _ = Command::new("kill")
        .args([&format!("-{signal}"), &pid.to_string()])
        .status();
}

/// A pseudo-terminal's master and slave, both opened close-on-exec, so that no run another
/// test spawns meanwhile inherits them: a copy of the master in another process would keep
/// the terminal from hanging up when this test closes its own (until the forty-fourth
/// session the master was made close-on-exec only after `openpty` had returned).
#[cfg(target_os = "linux")]
fn open_pty() -> Option<(std::os::fd::OwnedFd, std::os::fd::OwnedFd)> {
    use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
    // SAFETY: each descriptor is owned as soon as it is opened; `name` is a buffer of the
    // length passed, which `ptsname_r` NUL-terminates on success.
    unsafe {
        let master = libc::posix_openpt(libc::O_RDWR | libc::O_NOCTTY | libc::O_CLOEXEC);
        if master < 0 {
            return None;
        }
        let master = OwnedFd::from_raw_fd(master);
        if libc::grantpt(master.as_raw_fd()) != 0 || libc::unlockpt(master.as_raw_fd()) != 0 {
            return None;
        }
        let mut name = [0 as libc::c_char; 256];
        if libc::ptsname_r(master.as_raw_fd(), name.as_mut_ptr(), name.len()) != 0 {
            return None;
        }
        // Not our controlling terminal (`O_NOCTTY`): the run makes it its own.
        let slave = libc::open(
            name.as_ptr(),
            libc::O_RDWR | libc::O_NOCTTY | libc::O_CLOEXEC,
        );
        if slave < 0 {
            return None;
        }
        Some((master, OwnedFd::from_raw_fd(slave)))
    }
}

#[test]
#[cfg(target_os = "linux")]
fn a_hang_up_of_the_terminal_stops_the_run_cleanly() {
    // Found by the fortieth session's review: when the terminal hangs up, stderr is gone
    // (writes fail with EIO) and an `eprintln!` in the handler panicked, so the handler's
    // thread died before the exit and the run went on with nobody watching. Here the run's
    // stderr is the slave of a pseudo-terminal that is its controlling terminal; closing the
    // master hangs it up (SIGHUP, then EIO on every write).
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let Some((master, slave)) = open_pty() else {
        eprintln!("no pseudo-terminal on this machine: skipped");
        return;
    };
    let mut command = Command::new(env!("CARGO_BIN_EXE_swarmmap"));
    command
        .args(["simulate", "worlds/scenario2.ron", "--quiet", "--out"])
        .arg(&out)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::from(slave));
    hang_up_as_by_default(&mut command);
    // SAFETY: only async-signal-safe calls between fork and exec: a new session, then the
    // pseudo-terminal (now the child's stderr) as its controlling terminal.
    unsafe {
        command.pre_exec(|| {
            if libc::setsid() < 0 || libc::ioctl(2, libc::TIOCSCTTY, 0) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let mut child = command.spawn().unwrap();
    // Our copy of the slave went into the command; drop it so the master's close hangs up.
    drop(command);
    std::thread::sleep(std::time::Duration::from_millis(800));
    drop(master);
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > std::time::Duration::from_secs(20) {
            let _ = child.kill();
            panic!("the run went on after its terminal hung up");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    assert_eq!(
        (status.code(), status.signal()),
        (Some(130), None),
        "the hang-up did not stop the run through the handler (0: it went on to the end)"
    );
    for rel in files(&out).keys() {
        assert!(
            !rel.to_string_lossy().ends_with(".tmp"),
            "{rel:?} left behind"
        );
    }
}
