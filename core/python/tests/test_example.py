"""The planning example (scripts/examples/plan_path.py) runs, converges and
its path passes the independent check; its figure is written."""
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.normpath(os.path.join(HERE, "..", "..", "..", "scripts", "examples"))
sys.path.insert(0, EXAMPLES)

import plan_path  # noqa: E402


def test_planned_path_is_collision_free(tmp_path):
    png = tmp_path / "plan_path.png"
    path, s = plan_path.run(str(png), waypoints=40, threads=2)
    assert s["success"], s["message"]
    assert s["min_constraint"] > -1e-6
    # The check uses cold single solves and surface samples, not the batch the
    # optimiser used: every waypoint and 8 poses per segment.
    assert s["check"]["ok"] and s["check"]["solves"] == 40 * 6
    assert s["check"]["min_alpha"] > 1.0 and s["check"]["min_phi"] > 0.0
    assert s["between"]["ok"] and s["between"]["solves"] == (39 * 8 + 1) * 6
    # The path goes around the obstacles: longer than the straight line.
    assert s["length"] > 10.05
    assert png.stat().st_size > 10000


def test_the_check_catches_a_colliding_path():
    """The straight line through the obstacles fails the same check."""
    import numpy as np
    straight = np.linspace(plan_path.START, plan_path.GOAL, 40)
    c = plan_path.check(straight, samples=50)
    assert not c["ok"] and c["min_alpha"] < 1.0


def test_example_script_exit_status(tmp_path):
    env = dict(os.environ)
    r = subprocess.run([sys.executable, os.path.join(EXAMPLES, "plan_path.py"), "-o", str(tmp_path / "p.png")],
                       env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "collision free" in r.stdout


def test_readme_python_example_runs():
    """The 10-line Python example of README.md ("Three examples": its first
    python block), run as written."""
    readme = os.path.join(HERE, "..", "..", "..", "README.md")
    text = open(readme).read()
    start = text.index("```python\n", text.index("## Three examples")) + len("```python\n")
    code = text[start:text.index("```", start)]
    assert "solve_batch" in code and len(code.splitlines()) <= 12
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "SolveStatus.Converged" in r.stdout and "(1000, 6)" in r.stdout and "ToiStatus.Impact" in r.stdout
