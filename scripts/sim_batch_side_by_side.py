#!/usr/bin/python3
"""batch / loop of two revisions' idcol_bench_sim_batch runs, made alternately.

  scripts/sim_batch_side_by_side.py DIR OLD NEW I [I ...]

reads DIR/OLD_I.json and DIR/NEW_I.json (Google Benchmark's JSON output,
--benchmark_out, with --benchmark_report_aggregates_only) for each run number
I and prints a Markdown table: each scene and mode's batch / loop (medians of
the run's repetitions) in every run of each revision, the batch's time in
microseconds beside it, and the provenance each file's context records; a
scene and mode that only one revision has shows "-" for the other. Exit 2 if a
file is missing, or a revision's runs hold different rows.
"""
import json
import sys


def load(path):
    try:
        with open(path) as f:
            d = json.load(f)
    except (OSError, ValueError) as e:
        print(f"sim_batch_side_by_side.py: cannot read {path}: {e}", file=sys.stderr)
        sys.exit(2)
    times = {}
    for b in d.get("benchmarks", []):
        if b.get("aggregate_name") != "median":
            continue
        scene, mode, path_ = b["run_name"].split("/")[:3]
        times[(scene, mode, path_)] = b["real_time"]
    rows = {}
    for (scene, mode, path_), t in times.items():
        if path_ == "batch" and (scene, mode, "loop") in times:
            rows[(scene, mode)] = (times[(scene, mode, "loop")] / t, t)
    ctx = d.get("context", {})
    prov = ", ".join(f"{k[6:]} {ctx[k]}" for k in ("idcol_git_revision", "idcol_compiler", "idcol_flags", "idcol_cpu")
                     if k in ctx)
    return rows, prov or "no provenance recorded"


def main(argv):
    if len(argv) < 5:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    d, old, new, runs = argv[1], argv[2], argv[3], argv[4:]
    O = [load(f"{d}/{old}_{i}.json") for i in runs]
    N = [load(f"{d}/{new}_{i}.json") for i in runs]
    for X in (O, N):
        if any(sorted(rows) != sorted(X[0][0]) for rows, _ in X):
            print("sim_batch_side_by_side.py: one revision's runs hold different scenes or modes", file=sys.stderr)
            return 2
    keys = list(O[0][0]) + [k for k in N[0][0] if k not in O[0][0]]  # a scene one revision lacks: "-"
    print(f"| scene, mode | {old}: batch / loop (batch us), runs {', '.join(runs)} | {new}: the same |")
    print("|---|---|---|")
    for k in keys:
        cells = [", ".join(f"{r[k][0]:.2f}x ({r[k][1]:.0f})" for r, _ in X) if k in X[0][0] else "-" for X in (O, N)]
        print(f"| {k[0]} {k[1]} | {cells[0]} | {cells[1]} |")
    print()
    for name, X in ((old, O), (new, N)):
        for i, (_, prov) in zip(runs, X):
            print(f"- {name}_{i}.json: {prov}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
