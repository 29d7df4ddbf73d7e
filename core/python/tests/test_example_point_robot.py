"""The point-robot example (scripts/examples/point_robot_gradient.py): 100
obstacles, one batch with derivatives per gradient step; it reaches the goal
without collision (checked by cold single solves), and the gradient it uses
matches finite differences of its potential."""
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.normpath(os.path.join(HERE, "..", "..", "..", "scripts", "examples"))
sys.path.insert(0, EXAMPLES)

import point_robot_gradient as ex  # noqa: E402


def test_reaches_the_goal_without_collision():
    path, s = ex.run(steps=400, seed=0, threads=2)
    assert s["reached"] and len(s["obstacles"]) == 100
    c = ex.check(s["obstacles"], s["robot"], path)
    assert c["ok"] and c["min_alpha"] > 1.0 and c["solves"] == len(path) * 100
    assert s["min_gap"] > 0.0
    # It went around obstacles (longer than the straight line) and the
    # potential fell from start to goal.
    assert s["length"] > np.linalg.norm(ex.GOAL - ex.START) + 0.1
    assert s["costs"][-1] < 0.01 * s["costs"][0]


def test_the_check_catches_the_straight_line():
    obs = ex.obstacles(0)
    straight = np.linspace(ex.START, ex.GOAL, 200)
    c = ex.check(obs, ex.idcol.Sphere(R=ex.ROBOT_R), straight)
    assert not c["ok"]


def test_gradient_matches_finite_differences_of_the_potential():
    """d gap/dq = dgap_dxi[:, 3:] (the robot does not rotate): the potential's
    gradient against central differences in world coordinates, at points of
    the path where the repulsion acts."""
    path, s = ex.run(steps=400, seed=0, threads=1)
    obs, robot = s["obstacles"], s["robot"]
    h = 1e-6
    checked = 0
    for q in path[::10]:
        gap, dgap_dq = ex.gaps_and_gradients(obs, robot, q, threads=1)
        if gap.min() >= ex.CLEARANCE:
            continue
        g = ex.gradient(gap, dgap_dq, q)
        fd = np.zeros(3)
        for j in range(3):
            e = np.zeros(3)
            e[j] = h
            up = ex.potential(ex.gaps_and_gradients(obs, robot, q + e, 1)[0], q + e)
            dn = ex.potential(ex.gaps_and_gradients(obs, robot, q - e, 1)[0], q - e)
            fd[j] = (up - dn) / (2 * h)
        assert np.allclose(g, fd, rtol=1e-5, atol=1e-6), (q, g, fd)
        checked += 1
    assert checked >= 3


def test_example_script_exit_status():
    r = subprocess.run([sys.executable, os.path.join(EXAMPLES, "point_robot_gradient.py")], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "collision free" in r.stdout and "goal reached" in r.stdout
