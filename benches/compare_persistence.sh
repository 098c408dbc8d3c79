#!/usr/bin/env bash
# Times `swarmmap persistence` against ripser.py, GUDHI and giotto-ph on the same inputs
# (issue #3 §5) and prints one Markdown table: input, tool, seconds, peak MiB, H1 bars,
# ratio to the fastest peer.
#
# Usage: benches/compare_persistence.sh [--quick]
#   --quick   only n = 500 and 1000 (a smoke run)
# Environment: VENV (default .venv-bench), OUT (default target/compare-persistence).
#
# Every run is a separate process under `/usr/bin/time -v` (peak RSS of the whole process,
# interpreter included). Seconds: for the Python tools the call itself, timed inside the
# process (imports and reading the input excluded); for swarmmap the whole process
# (reading the CSV and printing included), so the comparison errs against swarmmap.
# One thread each unless the tool name says otherwise. Inputs are generated with fixed
# seeds, so reruns time the same data.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv-bench}
OUT=${OUT:-target/compare-persistence}
SIZES="500 1000 2000 4000"
if [[ "${1:-}" == "--quick" ]]; then SIZES="500 1000"; fi

if [[ ! -x "$VENV/bin/python" ]]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install --quiet --upgrade pip
    "$VENV/bin/pip" install --quiet numpy scikit-learn ripser gudhi giotto-ph
fi
cargo build --release --quiet
BIN=$(cargo metadata --format-version 1 --no-deps | "$VENV/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release/swarmmap
mkdir -p "$OUT"

"$VENV/bin/python" - "$OUT" "$BIN" $SIZES <<'PY'
import os, re, subprocess, sys
import numpy as np

out, binary, sizes = sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3:]]

def save(name, x):
    path = os.path.join(out, name + ".csv")
    np.savetxt(path, x, delimiter=",", fmt="%.17g")
    return path

inputs = []
for n in sizes:
    rng = np.random.default_rng(n)
    inputs.append((f"uniform2d_{n}", save(f"uniform2d_{n}", rng.random((n, 2)))))
rng = np.random.default_rng(7)
th = rng.uniform(0, 2 * np.pi, 1000)
circle = np.c_[np.cos(th), np.sin(th)] + 0.05 * rng.standard_normal((1000, 2))
inputs.append(("noisy_circle_1000", save("noisy_circle_1000", circle)))
rng = np.random.default_rng(8)
u, v = rng.uniform(0, 2 * np.pi, (2, 1000))
torus = np.c_[(2 + np.cos(v)) * np.cos(u), (2 + np.cos(v)) * np.sin(u), np.sin(v)]
inputs.append(("torus3d_1000", save("torus3d_1000", torus)))

worker = os.path.join(out, "worker.py")
with open(worker, "w") as f:
    f.write(r'''
import sys, time
import numpy as np
tool, path, threads = sys.argv[1], sys.argv[2], int(sys.argv[3])
x = np.loadtxt(path, delimiter=",")
if tool == "ripser.py":
    from ripser import ripser
    t = time.perf_counter(); dgms = ripser(x, maxdim=1)["dgms"]; t = time.perf_counter() - t
    h1 = dgms[1]
elif tool == "gudhi":
    from gudhi.sklearn.rips_persistence import RipsPersistence
    rp = RipsPersistence(homology_dimensions=[0, 1], n_jobs=threads)
    t = time.perf_counter(); dgms = rp.fit_transform([x])[0]; t = time.perf_counter() - t
    h1 = dgms[1]
else:
    from gph import ripser_parallel
    t = time.perf_counter(); dgms = ripser_parallel(x, maxdim=1, n_threads=threads)["dgms"]; t = time.perf_counter() - t
    h1 = dgms[1]
h1 = np.asarray(h1).reshape(-1, 2)
print(t, int(np.sum(h1[:, 1] - h1[:, 0] > 1e-6 * np.maximum(np.abs(h1[:, 1]), 1e-300))))
''')

def timed(cmd):
    r = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True, check=True)
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1)) / 1024
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (.*)", r.stderr).group(1)
    secs = sum(float(p) * 60 ** i for i, p in enumerate(reversed(wall.split(":"))))
    return r.stdout, secs, rss

rows = []
for name, path in inputs:
    res = []
    for tool, threads in [("ripser.py", 1), ("gudhi", 1), ("giotto-ph", 1), ("giotto-ph", 2)]:
        stdout, _, rss = timed([sys.executable, worker, tool, path, str(threads)])
        secs, h1 = stdout.split()
        label = tool if threads == 1 else f"{tool} ({threads} threads)"
        res.append((label, float(secs), rss, int(h1), True))
    for threads in (1, 2):
        stdout, secs, rss = timed([binary, "persistence", path, "--threads", str(threads)])
        h1 = 0
        for line in stdout.splitlines()[1:]:
            d, b, e = line.split(",")
            if d == "1" and float(e) - float(b) > 1e-6 * abs(float(e)):
                h1 += 1
        label = "swarmmap" if threads == 1 else f"swarmmap ({threads} threads)"
        res.append((label, secs, rss, h1, False))
    best = min(s for _, s, _, _, peer in res if peer)
    for label, s, rss, h1, _ in res:
        rows.append((name, label, s, rss, h1, s / best))
    print(f"done {name}", file=sys.stderr, flush=True)

print("| input | tool | seconds | peak MiB | H1 bars | ratio to fastest peer |")
print("|---|---|---:|---:|---:|---:|")
for name, label, s, rss, h1, ratio in rows:
    print(f"| {name} | {label} | {s:.3f} | {rss:.0f} | {h1} | {ratio:.2f} |")
PY
