#!/usr/bin/env python3
"""ctest docs.side_by_side: scripts/sim_batch_side_by_side.py on made-up
runs of two revisions, and scripts/sim_step_split.py on a made-up run. Each
case says what it must answer:

  - a scene and mode both revisions ran: both revisions' batch / loop and
    the batch's time, in every run;
  - a scene only the newer revision has (a benchmark added since): its
    row, with "-" for the older revision;
  - one revision's runs holding different rows: exit 2, saying so;
  - a missing file: exit 2, naming it;
  - the split of the step: each scene's row, and the bound that the rows
    Separated at once set (the loop's step over their part);
  - a run without one of the split's scenes: exit 2, naming it.

    scripts/tests/sim_batch_side_by_side_test.py   # exit 0: every case as expected
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(os.path.dirname(HERE), "sim_batch_side_by_side.py")
SPLIT = os.path.join(os.path.dirname(HERE), "sim_step_split.py")


def write_run(path, rows, revision=None):
    """rows: {(scene, mode): (loop_us, batch_us)} as Google Benchmark's medians."""
    benchmarks = []
    for (scene, mode), (loop, batch) in rows.items():
        for path_, t in (("loop", loop), ("batch", batch)):
            benchmarks.append({"run_name": f"{scene}/{mode}/{path_}/min_time:0.300/real_time",
                               "aggregate_name": "median", "real_time": t})
    context = {"idcol_git_revision": revision} if revision else {}
    with open(path, "w") as f:
        json.dump({"context": context, "benchmarks": benchmarks}, f)


def run(*args, script=SCRIPT):
    p = subprocess.run([sys.executable, script, *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def main():
    failures = []

    def expect(cond, what):
        if not cond:
            failures.append(what)

    with tempfile.TemporaryDirectory() as d:
        common = {("ten64", "warm_deriv"): (1200.0, 1000.0)}
        for i in ("1", "2"):
            write_run(f"{d}/old_{i}.json", common, "old")
            write_run(f"{d}/new_{i}.json", {**common, ("ten64_live", "warm_deriv"): (700.0, 350.0)}, "new")
        rc, out, err = run(d, "old", "new", "1", "2")
        expect(rc == 0, f"two revisions: exit {rc}: {err}")
        expect("| ten64 warm_deriv | 1.20x (1000), 1.20x (1000) | 1.20x (1000), 1.20x (1000) |" in out,
               f"the common row: {out}")
        expect("| ten64_live warm_deriv | - | 2.00x (350), 2.00x (350) |" in out, f"the new scene's row: {out}")
        expect("old_1.json: git_revision old" in out, f"the provenance: {out}")

        write_run(f"{d}/new_2.json", common, "new")  # the newer revision's runs differ
        rc, out, err = run(d, "old", "new", "1", "2")
        expect(rc == 2 and "different scenes or modes" in err, f"runs that differ: exit {rc}: {err}")

        rc, out, err = run(d, "old", "new", "1", "3")
        expect(rc == 2 and "old_3.json" in err, f"a missing file: exit {rc}: {err}")

        split = {("ten", "warm_deriv"): (12.0, 12.0), ("ten_live", "warm_deriv"): (7.0, 7.0),
                 ("ten_separated", "warm_deriv"): (6.0, 6.0), ("ten64", "warm_deriv"): (1200.0, 1000.0),
                 ("ten64_live", "warm_deriv"): (800.0, 560.0), ("ten64_separated", "warm_deriv"): (400.0, 440.0)}
        write_run(f"{d}/split.json", split, "new")
        rc, out, err = run(f"{d}/split.json", script=SPLIT)
        expect(rc == 0, f"the split: exit {rc}: {err}")
        expect("| ten64_live | - | 800.0 | 560.0 | 1.43x |" in out, f"the split's row: {out}")
        expect("- ten: the rows Separated at once take 0.50 of the loop's step" in out and "at most 2.00x" in out,
               f"the ten-body step's bound: {out}")
        expect("at most 3.00x" in out, f"ten64's bound: {out}")
        del split[("ten_separated", "warm_deriv")]
        write_run(f"{d}/split.json", split, "new")
        rc, out, err = run(f"{d}/split.json", script=SPLIT)
        expect(rc == 2 and "ten_separated" in err, f"a scene missing from the split: exit {rc}: {err}")

    for f in failures:
        print("FAIL:", f)
    print(f"{'FAILED' if failures else 'ok'}: sim_batch_side_by_side.py and sim_step_split.py, {len(failures)} case(s) failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
