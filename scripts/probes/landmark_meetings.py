"""Probe of docs/accuracy.md, step 50: how many encounters a landmark interval gathers.

Not part of the build or the tests; Python 3's standard library only. Reads run directories
written by `swarmmap simulate WORLD --seed N --out DIR` (or `run`) and prints, per
directory, the landmark static intervals (`static_intervals.csv`, reason `landmark`), how
many encounters meet each (an encounter of the landmark's agent whose interval meets the
static interval), the quartiles of those counts among the intervals met at least once, and
the median length of the intervals longer than 60 s (the landmarks that stood while the
domain passed; most intervals are brief replacements).

    python3 scripts/probes/landmark_meetings.py runs/s2-seed7 runs/s3-seed7
"""
import bisect
import csv
import statistics
import sys
from collections import defaultdict


def probe(run):
    intervals = defaultdict(list)
    with open(f"{run}/static_intervals.csv", newline="") as f:
        for row in csv.DictReader(f):
            if row["reason"] == "landmark":
                intervals[int(row["agent"])].append((float(row["start"]), float(row["end"])))
    for spans in intervals.values():
        spans.sort()
    met = defaultdict(int)
    with open(f"{run}/encounters.csv", newline="") as f:
        for row in csv.DictReader(f):
            start, end = float(row["start"]), float(row["end"])
            for agent in (int(row["a"]), int(row["b"])):
                spans = intervals.get(agent)
                if not spans:
                    continue
                i = bisect.bisect_right(spans, (end, float("inf"))) - 1
                while i >= 0 and spans[i][1] >= start:
                    if spans[i][0] <= end:
                        met[(agent, i)] += 1
                    i -= 1
    counts = [met.get((a, i), 0) for a, spans in intervals.items() for i in range(len(spans))]
    positive = sorted(c for c in counts if c > 0)
    q = lambda p: positive[int(p * (len(positive) - 1))] if positive else 0
    long = [e - s for spans in intervals.values() for s, e in spans if e - s > 60]
    print(
        f"{run}: {len(counts)} landmark intervals, {len(positive)} met; encounters per met "
        f"interval, quartiles 25/50/75/90 %: {q(.25)} {q(.5)} {q(.75)} {q(.9)}; "
        f"{len(long)} intervals over 60 s, median length "
        f"{statistics.median(long) if long else 0:.1f} s"
    )


if __name__ == "__main__":
    for run in sys.argv[1:]:
        probe(run)
