"""The type stubs shipped in the package (idcol/__init__.pyi) agree with the
module (mypy's stubtest: every public name and member present on both
sides) and type-check a program using the API (mypy --strict)."""
import os
import subprocess
import sys

import pytest

import idcol

mypy = pytest.importorskip("mypy", reason="mypy is not installed (Debian: python3-mypy, scripts/setup.sh)")
HERE = os.path.dirname(os.path.abspath(__file__))
PKG_ROOT = os.path.dirname(os.path.dirname(idcol.__file__))


def run(args):
    env = dict(os.environ, MYPYPATH=PKG_ROOT, PYTHONPATH=PKG_ROOT)
    return subprocess.run([sys.executable, "-m"] + args, capture_output=True, text=True, env=env, cwd=HERE)


def test_stubs_ship_with_the_package():
    d = os.path.dirname(idcol.__file__)
    assert os.path.exists(os.path.join(d, "__init__.pyi")) and os.path.exists(os.path.join(d, "py.typed"))


def test_stubs_match_the_module():
    proc = run(["mypy.stubtest", "idcol", "--allowlist", os.path.join(HERE, "stubtest_allowlist.txt"),
                "--ignore-unused-allowlist"])
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]


def test_a_typed_program_checks_strictly():
    proc = run(["mypy", "--strict", "--no-incremental", "--cache-dir", "/dev/null", os.path.join(HERE, "typing_usage.py")])
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]


def test_the_typed_program_runs():
    sys.path.insert(0, HERE)
    try:
        import typing_usage
    finally:
        sys.path.pop(0)
    import numpy as np
    s = idcol.Sphere(0.2)
    q = typing_usage.plan_step(s, [idcol.Sphere(1.0), idcol.Superellipsoid(0.5, 0.7, 0.9)], np.array([2.0, 0.5, 0.1]))
    assert q.shape == (3,) and np.isfinite(q).all()
    assert np.isfinite(typing_usage.one_query())
    p0 = np.array([[2.0, 0.0, 0.0], [np.nan, 0.0, 0.0]])
    assert typing_usage.sweep(s, s, p0, -p0) == {1: "p0[1][0] = nan is not finite"}
