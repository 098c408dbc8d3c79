//! Encounter detection (paper §"Exploration and Event Collection": an encounter is a time
//! interval during which two agents are within r_d of each other), on a thread of its own.
//!
//! The simulation loop hands every configuration (the agents' positions at step k, before
//! the step) to a [`Detector`], which runs the sensing world ([`SensorWorld`]) on it and
//! turns its sensor events into encounters: an encounter starts at the first step time at
//! which the centres are within r_d and ends at the first step time at which they are not.
//! Sensors never act on the motion (landmark selection reads positions, not encounters),
//! so the detector may run behind the physics: the loop sends it configurations in batches
//! and hears back only when a cut of [`SimOptions::with_prefixes`] is settled and at the
//! end of the run. On two cores the physics and the sensing then share the work of a step
//! (docs/speed.md, "Forty-sixth session").
//!
//! Determinism: the detector sees the same configurations in the same order whatever the
//! threads' timing, and a settled cut names the step that settled it, so the encounters,
//! the prefixes and the final log do not depend on the schedule.
//!
//! [`SimOptions::with_prefixes`]: super::SimOptions::with_prefixes

use super::physics::{RawEvent, SensorWorld};
use crate::log::Encounter;
use std::collections::HashMap;
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::thread::JoinHandle;
use std::time::Instant;

type P = (f64, f64);

/// Configurations of consecutive steps: the first one's step, their number, and their
/// positions one after another.
type Batch = (u64, usize, Vec<P>);

/// Positions per batch sent to the detector's thread (at least one configuration).
const BATCH_POSITIONS: usize = 4096;
/// Positions that may wait for the detector before the loop waits for it (at least one
/// batch): bounds the memory (4 MiB of queued batches below 4 096 agents; one batch of one
/// configuration, 16 bytes an agent, above) and how far the detector can fall behind
/// (64 batches of 4 096 / n configurations for n agents).
const QUEUED_POSITIONS: usize = 64 * BATCH_POSITIONS;

/// An encounter still running: its start time and both agents' positions then (the
/// encounter's `truth`).
type Open = (f64, [f64; 4]);

/// Turns configurations into encounters.
pub(crate) struct Detector {
    world: SensorWorld,
    dt: f64,
    /// Step of the final configuration (time `n_steps × dt`), where no cut is settled: the
    /// final log serves (as [`SimOptions::with_prefixes`](super::SimOptions::with_prefixes)
    /// says).
    n_steps: u64,
    cuts: Vec<f64>,
    next_cut: usize,
    open: HashMap<(u32, u32), Open>,
    encounters: Vec<Encounter>,
    events: Vec<RawEvent>,
    busy_s: f64,
}

/// A cut settled at step `step`: every encounter that started at or before the cut has
/// ended by then.
pub(crate) struct Settled {
    /// Index of the cut.
    pub cut: usize,
    /// Step whose configuration settled it.
    pub step: u64,
    /// The encounters that started at or before the cut (as the log will write their
    /// starts), in the order they ended.
    pub encounters: Vec<Encounter>,
}

/// What the detector found over the whole run.
pub(crate) struct Detected {
    /// Encounters that ended, in the order they ended.
    pub encounters: Vec<Encounter>,
    /// Encounters still running at the final configuration.
    pub open: Vec<((u32, u32), Open)>,
    /// Time spent detecting, seconds (not deterministic).
    pub busy_s: f64,
}

impl Detector {
    /// A detector for a run of `n_steps` steps of `dt` seconds that settles `cuts`
    /// (ascending; empty for none).
    pub(crate) fn new(world: SensorWorld, dt: f64, n_steps: u64, cuts: &[f64]) -> Self {
        Self {
            world,
            dt,
            n_steps,
            cuts: cuts.to_vec(),
            next_cut: 0,
            open: HashMap::new(),
            encounters: Vec::new(),
            events: Vec::new(),
            busy_s: 0.0,
        }
    }

    /// Takes the configuration of step `k` and appends the cuts it settles to `settled`.
    fn observe(&mut self, k: u64, pos: &[P], settled: &mut Vec<Settled>) {
        let t0 = Instant::now();
        let t = k as f64 * self.dt;
        self.events.clear();
        self.world.detect(pos, &mut self.events);
        for &ev in &self.events {
            let RawEvent::Sensor { a, b, started } = ev else {
                continue;
            };
            if started {
                let (pa, pb) = (pos[a as usize], pos[b as usize]);
                self.open
                    .entry((a, b))
                    .or_insert((t, [pa.0, pa.1, pb.0, pb.1]));
            } else if let Some((start, truth)) = self.open.remove(&(a, b)) {
                self.encounters.push(Encounter {
                    start,
                    end: t,
                    a,
                    b,
                    truth: Some(truth),
                });
            }
        }
        if k < self.n_steps {
            // The final log's windows take its rounded starts (`as_written`): so do the cuts.
            let written = |x: f64| crate::log::written(x, &mut String::new());
            while let Some(&c) = self.cuts.get(self.next_cut) {
                if t < c || self.open.values().any(|&(start, _)| written(start) <= c) {
                    break;
                }
                settled.push(Settled {
                    cut: self.next_cut,
                    step: k,
                    encounters: self
                        .encounters
                        .iter()
                        .filter(|e| written(e.start) <= c)
                        .cloned()
                        .collect(),
                });
                self.next_cut += 1;
            }
        }
        self.busy_s += t0.elapsed().as_secs_f64();
    }

    fn finish(self) -> Detected {
        Detected {
            encounters: self.encounters,
            open: self.open.into_iter().collect(),
            busy_s: self.busy_s,
        }
    }
}

/// A [`Detector`] fed by the simulation loop: on its own thread, or on the loop's thread
/// where none can be started.
pub(crate) struct Sensing {
    agents: usize,
    /// Configurations per batch.
    per_batch: usize,
    /// Step of the batch's first configuration, how many it holds, and their positions.
    first: u64,
    configs: usize,
    batch: Vec<P>,
    mode: Mode,
}

enum Mode {
    Thread {
        to_detector: SyncSender<Batch>,
        settled: Receiver<Settled>,
        detector: JoinHandle<Option<Detected>>,
    },
    Inline {
        detector: Box<Detector>,
        settled: Vec<Settled>,
    },
}

impl Sensing {
    /// Starts `detector` for a swarm of `agents` on a thread of its own.
    pub(crate) fn start(detector: Detector, agents: usize) -> Self {
        let batch = Self::per_batch(agents) * agents;
        let queued = (QUEUED_POSITIONS / batch.max(1)).max(1);
        let (to_detector, batches) = mpsc::sync_channel::<Batch>(queued);
        let (settle, settled) = mpsc::channel();
        // The detector is handed over once the thread has started; where none can be
        // started it stays on this thread.
        let (hand, take) = mpsc::channel::<Detector>();
        let spawned = std::thread::Builder::new()
            .name("sensing".into())
            .spawn(move || {
                let mut detector = take.recv().ok()?;
                let mut out = Vec::new();
                for (first, configs, batch) in batches {
                    for j in 0..configs {
                        let pos = &batch[j * agents..(j + 1) * agents];
                        detector.observe(first + j as u64, pos, &mut out);
                        for s in out.drain(..) {
                            // The loop stops listening only once it has all it needs.
                            let _ = settle.send(s);
                        }
                    }
                }
                Some(detector.finish())
            });
        match spawned {
            Ok(handle) => match hand.send(detector) {
                Ok(()) => Self::with_mode(
                    agents,
                    Mode::Thread {
                        to_detector,
                        settled,
                        detector: handle,
                    },
                ),
                Err(mpsc::SendError(detector)) => Self::inline(detector, agents),
            },
            Err(_) => Self::inline(detector, agents),
        }
    }

    /// Runs `detector` on the loop's thread, as each batch is complete.
    fn inline(detector: Detector, agents: usize) -> Self {
        Self::with_mode(
            agents,
            Mode::Inline {
                detector: Box::new(detector),
                settled: Vec::new(),
            },
        )
    }

    /// Configurations per batch for a swarm of `agents`.
    fn per_batch(agents: usize) -> usize {
        (BATCH_POSITIONS / agents.max(1)).max(1)
    }

    fn with_mode(agents: usize, mode: Mode) -> Self {
        let per_batch = Self::per_batch(agents);
        Self {
            agents,
            per_batch,
            first: 0,
            configs: 0,
            batch: Vec::with_capacity(per_batch * agents),
            mode,
        }
    }

    /// Hands over the configuration of step `k` (steps come in order, from 0); `last` marks
    /// the final one.
    pub(crate) fn push(&mut self, k: u64, pos: &[P], last: bool) {
        if self.configs == 0 {
            self.first = k;
        }
        self.batch.extend_from_slice(pos);
        self.configs += 1;
        if last || self.configs >= self.per_batch {
            self.flush();
        }
    }

    fn flush(&mut self) {
        if self.configs == 0 {
            return;
        }
        let configs = std::mem::take(&mut self.configs);
        match &mut self.mode {
            Mode::Thread { to_detector, .. } => {
                let batch = std::mem::replace(
                    &mut self.batch,
                    Vec::with_capacity(self.per_batch * self.agents),
                );
                // A detector that stopped (it panicked) is reported by `finish`.
                let _ = to_detector.send((self.first, configs, batch));
            }
            Mode::Inline { detector, settled } => {
                for j in 0..configs {
                    let pos = &self.batch[j * self.agents..(j + 1) * self.agents];
                    detector.observe(self.first + j as u64, pos, settled);
                }
                self.batch.clear();
            }
        }
    }

    /// The cuts settled since the last call, in order.
    pub(crate) fn settled(&mut self) -> Vec<Settled> {
        match &mut self.mode {
            Mode::Thread { settled, .. } => settled.try_iter().collect(),
            Mode::Inline { settled, .. } => std::mem::take(settled),
        }
    }

    /// Waits for the detector to see every configuration handed over, and returns what it
    /// found and the cuts settled since the last [`Sensing::settled`].
    pub(crate) fn finish(mut self) -> (Detected, Vec<Settled>) {
        self.flush();
        match self.mode {
            Mode::Thread {
                to_detector,
                settled,
                detector,
            } => {
                drop(to_detector);
                let detected = match detector.join() {
                    Ok(Some(d)) => d,
                    Ok(None) => unreachable!("the detector was handed to its thread"),
                    Err(panic) => std::panic::resume_unwind(panic),
                };
                (detected, settled.try_iter().collect())
            }
            Mode::Inline { detector, settled } => (detector.finish(), settled),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::World;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const DT: f64 = 0.25;
    /// Positions lie on a grid of 1/64 m, so squared distances are multiples of 1/4096 m²,
    /// none within 1.5e-4 m² of r_d² = 0.09 m²: no pair sits at the boundary, where the
    /// sensing world's f32 test and this f64 oracle could disagree.
    const GRID: f64 = 1.0 / 64.0;
    const R_D: f64 = 0.3;

    /// A random walk of `n` agents on the grid inside a 2 m square, `steps + 1`
    /// configurations; some agents stand still for stretches, as landmarks do.
    fn walk(n: usize, steps: usize, seed: u64) -> Vec<Vec<P>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut cells: Vec<(i64, i64)> = (0..n)
            .map(|_| (rng.random_range(0..128), rng.random_range(0..128)))
            .collect();
        let mut out = Vec::new();
        for _ in 0..=steps {
            out.push(
                cells
                    .iter()
                    .map(|&(x, y)| (x as f64 * GRID, y as f64 * GRID))
                    .collect(),
            );
            for c in &mut cells {
                if rng.random_bool(0.2) {
                    continue;
                }
                c.0 = (c.0 + rng.random_range(-2..=2)).clamp(0, 127);
                c.1 = (c.1 + rng.random_range(-2..=2)).clamp(0, 127);
            }
        }
        out
    }

    fn world(n: usize) -> World {
        let mut w = World::empty("w", 2.0, 2.0);
        w.swarm.agents = n;
        w.swarm.detection_radius = R_D;
        w.simulation.dt = DT;
        w
    }

    /// Encounters by brute force: each pair's maximal runs of configurations with the
    /// centres within r_d, ending at the first configuration out of range (`None`: still in
    /// range at the last one).
    fn oracle(configs: &[Vec<P>]) -> Vec<(u32, u32, f64, Option<f64>)> {
        let n = configs[0].len();
        let mut out = Vec::new();
        for a in 0..n {
            for b in a + 1..n {
                let mut start = None;
                for (k, pos) in configs.iter().enumerate() {
                    let (p, q) = (pos[a], pos[b]);
                    let near = (p.0 - q.0).powi(2) + (p.1 - q.1).powi(2) <= R_D * R_D;
                    let t = k as f64 * DT;
                    match (near, start) {
                        (true, None) => start = Some(t),
                        (false, Some(s)) => {
                            out.push((a as u32, b as u32, s, Some(t)));
                            start = None;
                        }
                        _ => {}
                    }
                }
                if let Some(s) = start {
                    out.push((a as u32, b as u32, s, None));
                }
            }
        }
        out.sort_by(|x, y| x.partial_cmp(y).unwrap());
        out
    }

    fn found(d: &Detected) -> Vec<(u32, u32, f64, Option<f64>)> {
        let mut out: Vec<_> = d
            .encounters
            .iter()
            .map(|e| (e.a, e.b, e.start, Some(e.end)))
            .chain(d.open.iter().map(|&((a, b), (s, _))| (a, b, s, None)))
            .collect();
        out.sort_by(|x, y| x.partial_cmp(y).unwrap());
        out
    }

    #[test]
    fn encounters_are_the_runs_of_configurations_within_the_detection_radius() {
        let (n, steps) = (40, 400);
        let configs = walk(n, steps, 5);
        let mut detector = Detector::new(
            SensorWorld::new(&world(n), &configs[0], DT),
            DT,
            steps as u64,
            &[],
        );
        let mut settled = Vec::new();
        for (k, pos) in configs.iter().enumerate() {
            detector.observe(k as u64, pos, &mut settled);
        }
        let detected = detector.finish();
        let truth = oracle(&configs);
        assert!(
            truth.len() > 100,
            "{} encounters: too few to test",
            truth.len()
        );
        assert_eq!(found(&detected), truth);
        // Each encounter's truth holds both centres at its start.
        for e in &detected.encounters {
            let pos = &configs[(e.start / DT).round() as usize];
            let (p, q) = (pos[e.a as usize], pos[e.b as usize]);
            assert_eq!(e.truth, Some([p.0, p.1, q.0, q.1]));
        }
    }

    #[test]
    fn cuts_settle_once_every_encounter_begun_by_them_has_ended() {
        let (n, steps) = (40, 400);
        let configs = walk(n, steps, 9);
        let cuts = [10.0, 10.25, 40.0, 70.0, 99.75];
        let mut detector = Detector::new(
            SensorWorld::new(&world(n), &configs[0], DT),
            DT,
            steps as u64,
            &cuts,
        );
        let mut settled = Vec::new();
        for (k, pos) in configs.iter().enumerate() {
            detector.observe(k as u64, pos, &mut settled);
        }
        let truth = oracle(&configs);
        let mut expect_step = 0;
        let mut seen = Vec::new();
        for (i, &c) in cuts.iter().enumerate() {
            // The first step at or after the cut (and after the previous cut's) at which
            // every encounter begun by the cut has ended; none at the final configuration.
            let step = (expect_step..steps).find(|&k| {
                let t = k as f64 * DT;
                t >= c
                    && truth
                        .iter()
                        .all(|&(_, _, s, end)| s > c || end.is_some_and(|e| e <= t))
            });
            let Some(step) = step else { break };
            expect_step = step;
            let s = &settled[i];
            assert_eq!((s.cut, s.step), (i, step as u64), "cut {c}");
            let mut got: Vec<_> = s.encounters.iter().map(|e| (e.a, e.b, e.start)).collect();
            got.sort_by(|x, y| x.partial_cmp(y).unwrap());
            let want: Vec<_> = truth
                .iter()
                .filter(|e| e.2 <= c)
                .map(|&(a, b, s, _)| (a, b, s))
                .collect();
            assert_eq!(got, want, "cut {c}");
            seen.push(i);
        }
        assert_eq!(settled.len(), seen.len());
        assert!(seen.len() >= 3, "only {} cuts settled", seen.len());
    }

    #[test]
    fn the_thread_and_the_inline_detector_find_what_a_bare_detector_finds() {
        let (n, steps) = (40, 300);
        let configs = walk(n, steps, 13);
        let cuts = [20.0, 50.0];
        let make = || {
            Detector::new(
                SensorWorld::new(&world(n), &configs[0], DT),
                DT,
                steps as u64,
                &cuts,
            )
        };
        let mut direct = make();
        let mut settled = Vec::new();
        for (k, pos) in configs.iter().enumerate() {
            direct.observe(k as u64, pos, &mut settled);
        }
        let direct = direct.finish();
        let key = |s: &Settled| (s.cut, s.step, s.encounters.clone());
        for mut sensing in [Sensing::start(make(), n), Sensing::inline(make(), n)] {
            let mut heard = Vec::new();
            for (k, pos) in configs.iter().enumerate() {
                sensing.push(k as u64, pos, k == steps);
                heard.extend(sensing.settled());
            }
            let (detected, late) = sensing.finish();
            heard.extend(late);
            assert_eq!(detected.encounters, direct.encounters);
            assert_eq!(found(&detected), found(&direct));
            assert_eq!(
                heard.iter().map(key).collect::<Vec<_>>(),
                settled.iter().map(key).collect::<Vec<_>>()
            );
        }
    }
}
