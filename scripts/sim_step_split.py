#!/usr/bin/python3
"""Where the simulator's step goes: idcol_bench_sim_batch's split scenes.

  scripts/sim_step_split.py FILE.json

reads one run of idcol_bench_sim_batch (Google Benchmark's JSON output,
--benchmark_out, with --benchmark_report_aggregates_only) that holds the
warm_deriv rows of ten, ten_live, ten_separated, ten64, ten64_live and
ten64_separated, and prints a Markdown table (rows, the loop's and the
batch's median times, batch / loop) and, for ten and ten64, the share of
the loop's step that its rows Separated at once take, and the bound it sets:
with those rows at the loop's cost (the bound and the outputs' writes,
whichever path answers them) and the solved rows free, the step's
batch / loop is at most the loop's step over that part. Exit 2 if the file
is missing or lacks a scene.
"""
import json
import sys

SCENES = ("ten", "ten_live", "ten_separated", "ten64", "ten64_live", "ten64_separated")


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    try:
        with open(argv[1]) as f:
            d = json.load(f)
    except (OSError, ValueError) as e:
        print(f"sim_step_split.py: cannot read {argv[1]}: {e}", file=sys.stderr)
        return 2
    t, rows = {}, {}
    for b in d.get("benchmarks", []):
        if b.get("aggregate_name") != "median":
            continue
        scene, mode, path = b["run_name"].split("/")[:3]
        if mode == "warm_deriv":
            t[(scene, path)] = b["real_time"]
            rows[scene] = b.get("rows")
    missing = [s for s in SCENES if (s, "loop") not in t or (s, "batch") not in t]
    if missing:
        print(f"sim_step_split.py: {argv[1]} has no warm_deriv loop and batch for {', '.join(missing)}", file=sys.stderr)
        return 2
    print("| scene (warm_deriv) | rows | loop (us) | batch (us) | batch / loop |")
    print("|---|---:|---:|---:|---:|")
    for s in SCENES:
        n = f"{rows[s]:.0f}" if rows.get(s) is not None else "-"
        print(f"| {s} | {n} | {t[(s, 'loop')]:.1f} | {t[(s, 'batch')]:.1f} | {t[(s, 'loop')] / t[(s, 'batch')]:.2f}x |")
    print()
    for s in ("ten", "ten64"):
        step, sep = t[(s, "loop")], t[(s + "_separated", "loop")]
        print(f"- {s}: the rows Separated at once take {sep / step:.2f} of the loop's step; with them at the loop's "
              f"cost and the solved rows free, the step's batch / loop is at most {step / sep:.2f}x")
    ctx = d.get("context", {})
    prov = ", ".join(f"{k[6:]} {ctx[k]}" for k in ("idcol_git_revision", "idcol_compiler", "idcol_flags", "idcol_cpu")
                     if k in ctx)
    print(f"- {argv[1]}: {prov or 'no provenance recorded'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
