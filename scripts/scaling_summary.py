#!/usr/bin/env python3
"""The figures of a scripts/throughput_scaling.sh run in one JSON file, so
that the documentation can quote them (scripts/check_doc_figures.py):

    scripts/scaling_summary.py OUTDIR      # writes OUTDIR/summary.json

Under "cold" and "warm": speed_up, solve_batch's solves per second on T
threads over 1 thread, for the highest T of each pair, on POSES
(throughput.json) and on 10^6 poses (speed_up_large, large.json);
batch_over_loop, throughput.json's single-core rows; balance, the splits'
bounds at T threads. processes.N.MODE: N independent pinned single-thread
processes (processes.md), their aggregate batch solves per second over one
process's, and each process's median rates.
"""
import json
import os
import sys


def scaling(path):
    with open(path) as f:
        d = json.load(f)
    one, top = {}, {}
    for r in d.get("thread_scaling", []):
        key = r["pair"] + " " + r["mode"]
        if r["threads"] == 1:
            one[key] = r["solves_per_s"]
        if key not in top or r["threads"] > top[key]["threads"]:
            top[key] = r
    out = []
    for key, r in top.items():
        out.append({"pair": r["pair"], "mode": r["mode"], "threads": r["threads"],
                    "speed_up": r["solves_per_s"] / one[key]})
    return d, out


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: scaling_summary.py OUTDIR")
    out = sys.argv[1]
    d, small = scaling(os.path.join(out, "throughput.json"))
    dl, large = scaling(os.path.join(out, "large.json"))
    procs = []
    with open(os.path.join(out, "processes.md")) as f:
        for line in f:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) == 6 and cells[0].isdigit():
                procs.append({"processes": int(cells[0]), "pair": cells[1], "mode": cells[2],
                              "loop_per_process": float(cells[3]), "batch_per_process": float(cells[4]),
                              "aggregate_over_one": float(cells[5])})
    summary = {
        "source": out,
        "git_revision": d["git_revision"],
        "machine": d["machine"],
        "poses": d["poses_per_pair"],
        "large_poses": dl["poses_per_pair"],
    }
    for mode in ("cold", "warm"):
        summary[mode] = {
            "speed_up": [r for r in small if r["mode"] == mode],
            "speed_up_large": [r for r in large if r["mode"] == mode],
            "batch_over_loop": [{"pair": r["pair"], "ratio": r["batch_over_loop"]} for r in d["rows"] if r["mode"] == mode],
            "balance": [r for r in d.get("chunk_balance", []) if r["mode"] == mode],
        }
    summary["processes"] = {}
    for r in procs:
        summary["processes"].setdefault(str(r["processes"]), {}).setdefault(r["mode"], []).append(r)
    tmp = os.path.join(out, "summary.json.tmp")
    with open(tmp, "w") as f:
        json.dump(summary, f, indent=1)
        f.write("\n")
    os.replace(tmp, os.path.join(out, "summary.json"))


if __name__ == "__main__":
    main()
