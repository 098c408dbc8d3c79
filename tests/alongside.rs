//! Mapping while the simulation runs (`pipeline::run_world`, "Mapping while the simulation
//! runs") must write exactly what mapping the final log writes: the local maps, their
//! summaries and the connections computed from the log's prefixes are compared byte for
//! byte with those of the same run mapped after the simulation.

use std::fs;
use std::path::Path;
use swarmmap::pipeline::{ALONGSIDE_MAX_WINDOWS, Alongside, RunOptions, run_world};
use swarmmap::world::{WorldSpec, apply_assignment};

const TINY: &str = "tests/fixtures/worlds/tiny.ron";

/// Every file a run writes, `summary.json` without its wall-clock parts.
fn outputs(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for sub in ["", "maps"] {
        let mut names: Vec<_> = fs::read_dir(dir.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file())
            .collect();
        names.sort();
        for path in names {
            let name = path.strip_prefix(dir).unwrap().display().to_string();
            let mut bytes = fs::read(&path).unwrap();
            if name == "summary.json" {
                let mut v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                let o = v.as_object_mut().unwrap();
                o.remove("timings");
                o.remove("alongside");
                bytes = serde_json::to_vec(&v).unwrap();
            }
            if name == "meta.json" {
                // Wall-clock timings of the simulation.
                let mut v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                v.as_object_mut().unwrap().remove("timings");
                bytes = serde_json::to_vec(&v).unwrap();
            }
            files.push((name, bytes));
        }
    }
    files
}

#[test]
fn mapping_alongside_the_simulation_writes_what_mapping_afterwards_writes() {
    let tmp = tempfile::tempdir().unwrap();
    // Each variant runs after the simulation, alongside it freely (twenty windows come
    // faster than the worker maps them, so some prefixes are left to the final pass) and
    // in lockstep (the worker maps every prefix handed out but the last); past
    // `ALONGSIDE_MAX_WINDOWS` nothing runs alongside.
    let variants: [&[&str]; 6] = [
        &["mapping.windows=4"],
        // Cuts at 85.1 and 155.1 s, where the step at 1702 · 0.05 = 85.10000000000001 s is written
        // (and mapped) as 85.1: the prefix must cut the rounded starts too (found by the
        // forty-first session's review).
        &[
            "mapping.windows=3",
            "mapping.overlap=30.2",
            "swarm.agents=200",
        ],
        &[
            "mapping.windows=5",
            "mapping.method=Paper",
            "swarm.agents=60",
        ],
        &["mapping.windows=3", "mapping.switch_cost=1.0", "seed=8"],
        &[
            "mapping.windows=20",
            "mapping.overlap=5",
            "swarm.agents=120",
        ],
        &["mapping.windows=70", "mapping.overlap=1"],
    ];
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    for (v, sets) in variants.iter().enumerate() {
        let mut spec = WorldSpec::load(Path::new(TINY)).unwrap();
        for s in *sets {
            apply_assignment(&mut spec, s).unwrap();
        }
        let world = spec.check().unwrap();
        let mut dirs = Vec::new();
        for mode in [Alongside::Off, Alongside::Free, Alongside::Lockstep] {
            let dir = tmp.path().join(format!("{v}-{mode:?}"));
            let opts = RunOptions {
                seed: world.seed,
                out: Some(dir.clone()),
                trajectories: None,
                progress: None,
                alongside: mode,
            };
            let (_, mapped) = run_world(&world, &opts).unwrap();
            let windows = world.mapping.windows;
            let busy = &mapped.summary.alongside;
            if mode == Alongside::Off || cores == 1 || windows > ALONGSIDE_MAX_WINDOWS {
                assert!(busy.is_empty(), "{sets:?} {mode:?}: {busy:?}");
            } else {
                // The worker always rasterises the free space first.
                assert!(
                    busy.contains_key("evaluation"),
                    "{sets:?} {mode:?}: {busy:?}"
                );
                if mode == Alongside::Lockstep {
                    // Every prefix handed out is mapped by the worker, and each of these
                    // runs hands out at least two consecutive ones (the last window's is
                    // never handed out: the run's end settles it): the worker maps windows
                    // and connects two of them, whatever the load. (Without lockstep how
                    // much it does depends on the machine.)
                    let maps = busy.get("local maps").copied();
                    assert!(maps.is_some_and(|s| s > 0.0), "{sets:?}: {busy:?}");
                    assert!(busy.contains_key("stitching"), "{sets:?}: {busy:?}");
                }
            }
            dirs.push(dir);
        }
        for d in &dirs[1..] {
            let (a, b) = (outputs(&dirs[0]), outputs(d));
            assert_eq!(
                a.iter().map(|f| &f.0).collect::<Vec<_>>(),
                b.iter().map(|f| &f.0).collect::<Vec<_>>()
            );
            for ((name, x), (_, y)) in a.iter().zip(&b) {
                assert!(x == y, "{sets:?}, {}: {name} differs", d.display());
            }
        }
    }
}
