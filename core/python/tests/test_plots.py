"""The plotting scripts (scripts/plot_smoothing.py, scripts/plot_run.py) run on the
checked-in results, name their figures after the results files, and refuse
files of another schema. They read JSON only: no idcol module needed."""
import glob
import json
import os
import shutil
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
SCRIPTS = os.path.join(ROOT, "scripts")
RESULTS = os.path.join(ROOT, "results")
FAMILIES = ("polytope", "cone", "superellipsoid", "cylinder")


def run(script, *args):
    # The interpreter running the tests (it has matplotlib: CMake checks), not the shebang's.
    return subprocess.run([sys.executable, os.path.join(SCRIPTS, script), *args],
                          capture_output=True, text=True, timeout=300)


def need(*names):
    missing = [n for n in names if not os.path.exists(os.path.join(RESULTS, n))]
    if missing:
        pytest.skip(f"checked-in results missing: {missing}")


def nonempty_png(path):
    with open(path, "rb") as f:
        return f.read(8) == b"\x89PNG\r\n\x1a\n" and os.path.getsize(path) > 1000


def test_scripts_are_executable():
    for s in ("plot_smoothing.py", "plot_run.py"):
        assert os.access(os.path.join(SCRIPTS, s), os.X_OK), s


def test_plot_smoothing_on_checked_in_results(tmp_path):
    need(*(f"smoothing_{f}.json" for f in FAMILIES), "smoothing.md")
    # the glob also matches the *.failures.json files, which the script skips
    files = sorted(glob.glob(os.path.join(RESULTS, "smoothing_*.json")))
    md = tmp_path / "smoothing.md"
    combined = tmp_path / "smoothing_error_vs_time.png"
    r = run("plot_smoothing.py", *files, "-o", str(tmp_path), "--md", str(md), "--combined", str(combined))
    assert r.returncode == 0, r.stderr
    for f in FAMILIES:
        assert nonempty_png(tmp_path / f"smoothing_{f}.png"), f
    assert nonempty_png(combined)
    # the table is the checked-in one (family order fixed, whatever the glob's order)
    with open(os.path.join(RESULTS, "smoothing.md")) as f:
        assert md.read_text() == f.read()


def test_plot_smoothing_ignores_hostile_scene_name(tmp_path):
    need("smoothing_cone.json")
    with open(os.path.join(RESULTS, "smoothing_cone.json")) as f:
        res = json.load(f)
    res["name"] = "../escaped"
    work = tmp_path / "work"
    out = work / "out"
    out.mkdir(parents=True)
    src = work / "smoothing_cone.json"
    src.write_text(json.dumps(res))
    r = run("plot_smoothing.py", str(src), "-o", str(out), "--md", str(out / "s.md"))
    assert r.returncode == 0, r.stderr
    assert nonempty_png(out / "smoothing_cone.png")
    written = {os.path.relpath(os.path.join(d, n), tmp_path) for d, _, ns in os.walk(tmp_path) for n in ns}
    assert written == {"work/smoothing_cone.json", "work/out/smoothing_cone.png", "work/out/s.md"}, written


def test_plot_run_on_paper_table1(tmp_path):
    need("paper_table1.json")
    r = run("plot_run.py", os.path.join(RESULTS, "paper_table1.json"), "-o", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert nonempty_png(tmp_path / "paper_table1_times.png")
    assert nonempty_png(tmp_path / "paper_table1_iterations.png")


def test_plot_run_untimed_file_gets_iterations_only(tmp_path):
    need("uniform_so3.json")
    shutil.copy(os.path.join(RESULTS, "uniform_so3.json"), tmp_path / "u.json")
    r = run("plot_run.py", str(tmp_path / "u.json"))
    assert r.returncode == 0, r.stderr
    assert "no pass was timed" in r.stdout
    assert nonempty_png(tmp_path / "u_iterations.png")
    assert not (tmp_path / "u_times.png").exists()


def test_plot_run_rejects_other_schema(tmp_path):
    need("stress.json")
    r = run("plot_run.py", os.path.join(RESULTS, "stress.json"), "-o", str(tmp_path))
    assert r.returncode == 2
    assert "stress.json" in r.stderr and "idcol-harness-stress" in r.stderr
    assert os.listdir(tmp_path) == []
