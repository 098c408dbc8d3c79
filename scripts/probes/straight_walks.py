"""Probe of docs/accuracy.md, step 47: do straight walks between landmark sites confirm holes?

Not part of the build or the tests. Needs Python 3 with numpy, scipy and gudhi
(`python3 -m venv v && v/bin/pip install numpy scipy gudhi`). Reads run directories written
by `swarmmap run WORLD --seed N --out DIR --no-report` (their `encounters.csv` must carry the
truth columns, used only to align the plane for labelling and to give its unit in metres).

For each window it prints one JSON line: the H1 bars of the alpha complex of every mapped
encounter at its place on the shipped plane (similarity-aligned to the truth), each labelled
with the obstacle within 0.35 m of its void (the centroid of its death triangle), and each
bar's emptiness in two clouds of straight walks: landmark sites (mean place of a landmark
interval's encounters) joined, for every moving agent, between consecutive landmark
encounters at sites whose distance over v times the time between the encounters' middles
is at least 0.9, sampled every 5 cm; "emb" with the sites at their embedded places, "true"
at their true places. Emptiness: the largest distance from a 9 x 9 grid of ±0.2 m round the
void to the nearest walk point. With `--rules FILE...` it reads such lines back and prints
the (life, emptiness) thresholds that get most windows right.
"""
import csv
import json
import math
import sys

import numpy as np

V = 0.1
STRAIGHT = 0.9
STEP = 0.05


def seg_dist(p, a, b):
    a, b, p = np.asarray(a), np.asarray(b), np.asarray(p)
    d = b - a
    t = np.clip(np.dot(p - a, d) / max(np.dot(d, d), 1e-12), 0, 1)
    return float(np.linalg.norm(p - (a + t * d)))


def obstacle_dist(o, p):
    kind, v = next(iter(o.items()))
    if kind == "Circle":
        return max(0.0, float(np.linalg.norm(np.asarray(p) - v["center"])) - v["radius"])
    if kind == "Wall":
        return max(0.0, seg_dist(p, v["from"], v["to"]) - v["thickness"] / 2)
    if kind == "Rect":
        pts = [v["min"], [v["max"][0], v["min"][1]], v["max"], [v["min"][0], v["max"][1]]]
    else:
        pts = v["points"]
    n, inside = len(pts), False
    for i in range(n):
        (x1, y1), (x2, y2) = pts[i], pts[(i + 1) % n]
        if (y1 > p[1]) != (y2 > p[1]) and p[0] < x1 + (p[1] - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return 0.0 if inside else min(seg_dist(p, pts[i], pts[(i + 1) % n]) for i in range(n))


def similarity(x, y):
    """Least-squares similarity (reflections allowed) taking x onto y."""
    mx, my = x.mean(0), y.mean(0)
    u, s, vt = np.linalg.svd((x - mx).T @ (y - my))
    scale = s.sum() / ((x - mx) ** 2).sum()
    return lambda p: (np.asarray(p) - mx) @ (u @ vt) * scale + my


def alpha_bars(points, obstacles):
    import gudhi

    st = gudhi.AlphaComplex(points=points).create_simplex_tree()
    st.compute_persistence()
    bars = []
    for b, d in st.persistence_pairs():
        if len(b) != 2 or not d:
            continue
        birth, death = math.sqrt(st.filtration(b)), math.sqrt(st.filtration(d))
        if death - birth < 0.05:
            continue
        c = points[d].mean(0)
        dist = [obstacle_dist(o, c) for o in obstacles]
        k = int(np.argmin(dist)) if dist else None
        bars.append(dict(birth=birth, death=death, at=[float(c[0]), float(c[1])],
                         obstacle=k if dist and dist[k] < 0.35 else None))
    bars.sort(key=lambda x: x["birth"] - x["death"])
    return bars[:15]


def walk_cloud(sites, pos, walks):
    pts = [pos[s] for s in sites]
    for lst in walks.values():
        lst.sort()
        for (ta, sa), (tb, sb) in zip(lst, lst[1:]):
            if sa == sb or tb <= ta:
                continue
            a, b = pos[sa], pos[sb]
            d = float(np.linalg.norm(b - a))
            if d > 0.1 and d / (V * (tb - ta)) >= STRAIGHT:
                n = max(1, int(d / STEP))
                pts.extend(a + (b - a) * k / n for k in range(1, n))
    return np.array(pts)


def read_run(run):
    """A run directory's summary, obstacles, encounter rows and `site_of(agent, t)`: the
    landmark site (agent, k-th landmark interval) an agent stands at at time t, or None."""
    meta = json.load(open(f"{run}/meta.json"))
    summary = json.load(open(f"{run}/summary.json"))
    landmarks = {}
    for r in csv.DictReader(open(f"{run}/static_intervals.csv")):
        if r["reason"] == "landmark":
            landmarks.setdefault(int(r["agent"]), []).append((float(r["start"]), float(r["end"])))

    def site_of(agent, t):
        for k, (s, e) in enumerate(landmarks.get(agent, [])):
            if s <= t <= e:
                return (agent, k)
        return None

    rows = list(csv.DictReader(open(f"{run}/encounters.csv")))
    return summary, meta["world"]["obstacles"], rows, site_of


def probe(run):
    from scipy.spatial import cKDTree

    summary, obstacles, rows, site_of = read_run(run)
    for ws in summary["windows"]:
        window = json.load(open(f"{run}/maps/window_{ws['index']}.json"))
        placed = {ev["encounter"]: ev["point"][:2] for ev in window["events"]}
        true_site, emb_site, walks, places = {}, {}, {}, []
        for i in sorted(placed):
            r = rows[i]
            a, b = int(r["a"]), int(r["b"])
            middle = (float(r["start"]) + float(r["end"])) / 2
            places.append(placed[i])
            sa, sb = site_of(a, middle), site_of(b, middle)
            if (sa is None) == (sb is None):
                continue
            site, mover, at = (sa, b, (r["a_x"], r["a_y"])) if sa else (sb, a, (r["b_x"], r["b_y"]))
            true_site[site] = (float(at[0]), float(at[1]))
            emb_site.setdefault(site, []).append(placed[i])
            walks.setdefault(mover, []).append((middle, site))
        sites = sorted(true_site)
        t = np.array([true_site[s] for s in sites])
        e = np.array([np.mean(emb_site[s], 0) for s in sites])
        align = similarity(e, t)
        bars = alpha_bars(align(np.array(places)), obstacles)
        for name, at in (("emb", align(e)), ("true", t)):
            tree = cKDTree(walk_cloud(sites, {s: at[k] for k, s in enumerate(sites)}, walks))
            offsets = np.linspace(-0.2, 0.2, 9)
            grid = np.array([[dx, dy] for dx in offsets for dy in offsets])
            for bar in bars:
                bar["empty_" + name] = float(tree.query(grid + bar["at"])[0].max())
        print(json.dumps(dict(run=run, window=ws["index"], truth=ws["truth"], bars=bars)), flush=True)


def rules(files):
    recs = [json.loads(line) for f in files for line in open(f)]

    def right(r, life, empty):
        passing = [b for b in r["bars"] if b["death"] - b["birth"] >= life and b["empty_emb"] >= empty]
        found = {b["obstacle"] for b in passing if b["obstacle"] is not None}
        return len(passing) == r["truth"][1] and len(found) == len(passing)

    scored = []
    for life in [x / 100 for x in range(5, 40)]:
        for empty in [x / 100 for x in range(0, 60, 2)]:
            scored.append((sum(right(r, life, empty) for r in recs), life, empty))
    scored.sort(key=lambda x: -x[0])
    print(f"{len(recs)} windows; best (right, life m, emptiness m):", scored[:5])
    alone = max((sum(right(r, life, 0) for r in recs), life) for life in [x / 100 for x in range(5, 40)])
    print("life alone (right, life m):", alone)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--rules"]:
        rules(sys.argv[2:])
    else:
        for run in sys.argv[1:]:
            probe(run)
