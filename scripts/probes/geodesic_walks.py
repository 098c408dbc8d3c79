"""Probe of docs/accuracy.md, step 48: the moving encounters placed along the walks' geodesics.

Not part of the build or the tests. Needs Python 3 with numpy, scipy and gudhi
(`python3 -m venv v && v/bin/pip install numpy scipy gudhi`). Reads run directories written
by `swarmmap run WORLD --seed N --out DIR --no-report` (their `encounters.csv` must carry the
truth columns, used only to align the plane to metres and to label the bars). Run it from
this folder (it imports `straight_walks.py`):
`python3 geodesic_walks.py RUN... > F.jsonl`, then `python3 geodesic_walks.py --score F.jsonl`.

The idea. An encounter of two moving agents is placed by the shipped pipeline on or near the
straight segment between the landmark sites its agents met before and after it, across an
obstacle when the agent walked round it. A walk from site A to site B that took Δt seconds
stayed inside the ellipse with foci A and B and major axis v Δt (v the agents' top speed),
so when that ellipse is thin (semi-minor axis at most WIDTH) the walk drew a line of free
space. Those lines form the walk graph on the sites; an agent that walked round an obstacle
from A to B has no thin ellipse across it, so the graph's shortest path from A to B bends
round the obstacle. Each moving agent's place at time t between its landmark encounters
(t1, A) and (t2, B) is put at the fraction (t - t1) / (t2 - t1) of that path's length; an
encounter of two moving agents gets the mean of the places of those of its agents that have
one, and keeps its shipped place when neither has.

For each window it prints one JSON line: for each placement ("shipped", "straight" (the same
interpolation on the straight segment: the control), "geodesic", "bent" (the shipped place
moved by the mean, over the agents that have both, of each agent's geodesic place minus its
straight place) and "geodesic_true" (the sites at
their true places, a ceiling for the sites)), the alpha-complex H1 bars (life over 0.05 m) of
every mapped encounter, each labelled with the obstacle within 0.35 m of its void. With
`--score FILE...` it reads the lines back and prints, per placement, the windows the best
fixed life threshold gets right, the windows whose truth-count longest bars are exactly
their obstacles, and the geometric mean of the weakest obstacle bar over the strongest
other bar.
"""
import bisect
import json
import math
import sys

import numpy as np

from straight_walks import alpha_bars, read_run, similarity

V = 0.1
WIDTH = 0.15


def geodesic_places(events, site_pos, landmark_at, times):
    """Places of the moving encounters along the walk graph (None where no agent has a path)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import shortest_path

    sites = sorted(site_pos)
    index = {s: k for k, s in enumerate(sites)}
    pos = np.array([site_pos[s] for s in sites])
    visits = {}
    for i, ev in enumerate(events):
        if landmark_at[i] is not None:
            site, mover = landmark_at[i]
            visits.setdefault(mover, []).append((times[i], index[site]))
    rows, cols, vals = [], [], []
    for lst in visits.values():
        lst.sort()
        for (ta, a), (tb, b) in zip(lst, lst[1:]):
            if a == b:
                continue
            d = float(np.linalg.norm(pos[a] - pos[b]))
            reach = V * (tb - ta)
            if 0.5 * math.sqrt(max(reach * reach - d * d, 0.0)) <= WIDTH:
                rows += [a, b]
                cols += [b, a]
                vals += [max(d, 1e-6)] * 2
    n = len(sites)
    graph = coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()
    dist, pred = shortest_path(graph, directed=False, return_predecessors=True)

    def along(a, b, f):
        if a == b or not np.isfinite(dist[a, b]):
            return None
        path = [b]
        while path[-1] != a:
            path.append(pred[a, path[-1]])
        path.reverse()
        goal, walked = f * dist[a, b], 0.0
        for u, w in zip(path, path[1:]):
            step = float(np.linalg.norm(pos[w] - pos[u]))
            if walked + step >= goal:
                return pos[u] + (pos[w] - pos[u]) * ((goal - walked) / max(step, 1e-12))
            walked += step
        return pos[path[-1]]

    def straight(a, b, f):
        return None if a == b else pos[a] + (pos[b] - pos[a]) * f

    out = {"geodesic": {}, "straight": {}, "offset": {}}
    for i, ev in enumerate(events):
        if landmark_at[i] is not None:
            continue
        found = {"geodesic": [], "straight": [], "offset": []}
        for agent in (ev["a"], ev["b"]):
            lst = visits.get(agent, [])
            k = bisect.bisect_right(lst, (times[i], math.inf))
            if k == 0 or k == len(lst):
                continue
            (t1, a), (t2, b) = lst[k - 1], lst[k]
            if t2 - t1 <= 0:
                continue
            f = (times[i] - t1) / (t2 - t1)
            g, st = along(a, b, f), straight(a, b, f)
            if g is not None:
                found["geodesic"].append(g)
            if st is not None:
                found["straight"].append(st)
            # The same agent's two places: how far the geodesic moves it.
            if g is not None and st is not None:
                found["offset"].append(g - st)
        for name, places in found.items():
            if places:
                out[name][i] = np.mean(places, 0)
    return out


def probe(run):
    summary, obstacles, rows, site_of = read_run(run)
    for ws in summary["windows"]:
        window = json.load(open(f"{run}/maps/window_{ws['index']}.json"))
        events = window["events"]
        times = [(ev["start"] + ev["end"]) / 2 for ev in events]
        placed = np.array([ev["point"][:2] for ev in events])
        landmark_at, true_site, emb_site = [], {}, {}
        for i, ev in enumerate(events):
            r = rows[ev["encounter"]]
            sa, sb = site_of(ev["a"], times[i]), site_of(ev["b"], times[i])
            if (sa is None) == (sb is None):
                landmark_at.append(None)
                continue
            site, mover, at = (sa, ev["b"], (r["a_x"], r["a_y"])) if sa else (sb, ev["a"], (r["b_x"], r["b_y"]))
            true_site[site] = (float(at[0]), float(at[1]))
            emb_site.setdefault(site, []).append(placed[i])
            landmark_at.append((site, mover))
        sites = sorted(true_site)
        align = similarity(np.array([np.mean(emb_site[s], 0) for s in sites]),
                           np.array([true_site[s] for s in sites]))
        shipped = align(placed)
        clouds = {"shipped": shipped}
        emb_pos = {s: align(np.mean(emb_site[s], 0)) for s in sites}
        for name, site_pos in (("", emb_pos), ("_true", {s: np.array(true_site[s]) for s in sites})):
            got = geodesic_places(events, site_pos, landmark_at, times)
            got["bent"] = {i: shipped[i] + d for i, d in got.pop("offset").items()}
            for kind, places in got.items():
                if name and kind != "geodesic":
                    continue
                cloud = shipped.copy()
                for i, p in places.items():
                    cloud[i] = p
                clouds[kind + name] = cloud
                if not name:
                    moving = sum(1 for x in landmark_at if x is None)
                    clouds.setdefault("_covered", {})[kind] = len(places) / max(moving, 1)
        covered = clouds.pop("_covered")
        bars = {k: alpha_bars(c, obstacles) for k, c in clouds.items()}
        print(json.dumps(dict(run=run, window=ws["index"], truth=ws["truth"], covered=covered,
                              bars=bars)), flush=True)


def score(files):
    recs = [json.loads(line) for f in files for line in open(f)]
    for kind in recs[0]["bars"]:
        def right(r, life):
            passing = [b for b in r["bars"][kind] if b["death"] - b["birth"] >= life]
            found = {b["obstacle"] for b in passing if b["obstacle"] is not None}
            return len(passing) == r["truth"][1] and len(found) == len(passing)

        best = max((sum(right(r, x / 100) for r in recs), x / 100) for x in range(5, 60))
        ranked, ratios = 0, []
        for r in recs:
            bars = r["bars"][kind]
            top = bars[: r["truth"][1]]
            found = {b["obstacle"] for b in top if b["obstacle"] is not None}
            ranked += len(found) == len(top) == r["truth"][1]
            lives = {}
            for b in bars:
                if b["obstacle"] is not None:
                    lives[b["obstacle"]] = max(lives.get(b["obstacle"], 0), b["death"] - b["birth"])
            noise = max([b["death"] - b["birth"] for b in bars if b["obstacle"] is None] or [0.05])
            if r["truth"][1]:
                weakest = min(lives.values()) if len(lives) == r["truth"][1] else 0.01
                ratios.append(weakest / noise)
        gm = math.exp(np.mean(np.log(ratios))) if ratios else float("nan")
        print(f"{kind:14} windows {len(recs)}: best fixed life {best[0]} (life {best[1]} m), "
              f"ranked {ranked}, obstacle/noise {gm:.2f}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--score"]:
        score(sys.argv[2:])
    else:
        for run in sys.argv[1:]:
            probe(run)
