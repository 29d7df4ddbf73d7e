#!/usr/bin/env python3
"""ctest docs.side_by_side: scripts/sim_batch_side_by_side.py
on made-up runs of two revisions. Each case says what it must answer:

  - a scene and mode both revisions ran: both revisions' batch / loop and
    the batch's time, in every run;
  - a scene only the newer revision has (a benchmark added since): its
    row, with "-" for the older revision;
  - one revision's runs holding different rows: exit 2, saying so;
  - a missing file: exit 2, naming it.

    scripts/tests/sim_batch_side_by_side_test.py   # exit 0: every case as expected
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(os.path.dirname(HERE), "sim_batch_side_by_side.py")


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


def run(*args):
    p = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)
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

    for f in failures:
        print("FAIL:", f)
    print(f"{'FAILED' if failures else 'ok'}: sim_batch_side_by_side.py, {len(failures)} case(s) failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
