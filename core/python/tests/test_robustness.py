"""The module never crashes: allocations that cannot be made raise
MemoryError, objects made by __new__ without __init__ raise TypeError,
Ctrl-C stops a batch long before its end, thread counts are capped at the
CPUs the process may use, and result arrays are read-only."""
import os
import pickle
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import idcol

HERE = os.path.dirname(os.path.abspath(__file__))


def run_python(code, limit_bytes=None, timeout=60):
    """Runs code in a fresh interpreter (the module from this one's path),
    optionally with its address space capped, and returns the process."""
    pre = ""
    if limit_bytes is not None:
        pre = "import resource\nresource.setrlimit(resource.RLIMIT_AS, (%d, %d))\n" % (limit_bytes, limit_bytes)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([os.path.dirname(os.path.dirname(idcol.__file__)), HERE,
                                         env.get("PYTHONPATH", "")])
    return subprocess.run([sys.executable, "-c", pre + textwrap.dedent(code)], capture_output=True, text=True,
                          env=env, timeout=timeout)


@pytest.mark.parametrize("code", [
    # 10^9 broadcast poses: the float64 copy (72 GB) does not fit.
    """
    import numpy as np, idcol
    R = np.broadcast_to(np.eye(3), (10**9, 3, 3)); p = np.broadcast_to(np.ones(3), (10**9, 3))
    idcol.solve_batch(idcol.Sphere(1.0), idcol.Sphere(1.0), R, p)
    """,
    # 10^9 float32 broadcast poses: the converted copy does not fit either.
    """
    import numpy as np, idcol
    R = np.broadcast_to(np.eye(3, dtype=np.float32), (10**9, 3, 3)); p = np.broadcast_to(np.ones(3), (10**9, 3))
    idcol.solve_batch(idcol.Sphere(1.0), idcol.Sphere(1.0), R, p)
    """,
    # 10^10 vertex rows.
    """
    import numpy as np, idcol
    idcol.SmoothPolytope.from_vertices(np.broadcast_to(np.ones(3), (10**10, 3)), beta=20)
    """,
    # 2 * 10^8 contiguous poses fit (1.6 GB + 0.5 GB) but the outputs do not.
    """
    import numpy as np, idcol
    n = 10**8
    R = np.zeros((n, 3, 3)); p = np.zeros((n, 3))
    idcol.solve_batch(idcol.Sphere(1.0), idcol.Sphere(1.0), R, p)
    """,
])
def test_allocations_that_do_not_fit_raise_memory_error(code):
    body = textwrap.indent(textwrap.dedent(code), "    ")
    wrapped = "import sys\ntry:\n%s\nexcept MemoryError as e:\n    print('MemoryError', e)\n    sys.exit(3)\n" % body
    proc = run_python(wrapped, limit_bytes=4 << 30)
    assert proc.returncode == 3 and proc.stdout.startswith("MemoryError"), (proc.returncode, proc.stderr[-2000:])


def _classes():
    s = idcol.Sphere(1.0)
    return [
        (idcol.Shape, lambda o: o.family),
        (idcol.Sphere, lambda o: o.R),
        (idcol.Superellipsoid, lambda o: o.eval([0.1, 0.2, 0.3])),
        (idcol.SmoothPolytope, lambda o: o.vertices),
        (idcol.ContactPair, lambda o: o.solve(np.eye(3), [3.0, 0.0, 0.0])),
        (idcol.BatchResult, lambda o: o.alpha),
        (idcol.ShapeKinematicsDerivatives, lambda o: o.dgap_dtheta),
        (idcol.ShapeWrenchDerivatives, lambda o: o.dF1_dtheta),
        (idcol.ShapeSensitivity, lambda o: o.dz_dtheta),
        (idcol.SolveResult, lambda o: o.alpha),
        (idcol.ContactKinematics, lambda o: o.p1),
        (idcol.ContactWrench, lambda o: o.F1),
        (idcol.Conditioning, lambda o: o.pivot_ratio),
        (idcol.SolutionSensitivity, lambda o: o.dz_dxi),
        (idcol.ToiResult, lambda o: o.t),
        (idcol.ToiBatchResult, lambda o: o.t),
        (idcol.ToiOptions, lambda o: idcol.time_of_impact(s, s, np.eye(3), [3.0, 0, 0], np.eye(3), [4.0, 0, 0],
                                                          options=o)),
        (idcol.Sphere, lambda o: idcol.solve(o, s, np.eye(3), [3.0, 0.0, 0.0])),
        (idcol.Sphere, lambda o: idcol.solve_batch(s, o, np.eye(3)[None], [[3.0, 0.0, 0.0]])),
        (idcol.Sphere, lambda o: idcol.solve_batch([(s, o)], np.eye(3)[None], [[3.0, 0.0, 0.0]])),
    ]


@pytest.mark.parametrize("cls, use", _classes(), ids=lambda x: getattr(x, "__name__", ""))
def test_objects_made_by_new_without_init_raise_type_error(cls, use):
    """Either __new__ itself refuses (classes with no Python constructor) or
    the first use of the empty object does; never a read of uninitialised
    memory (run under a sanitizer or valgrind, this would show)."""
    with pytest.raises(TypeError, match=r"__new__|cannot be created from Python"):
        obj = cls.__new__(cls)
        use(obj)


def _bound_classes():
    return [c for c in vars(idcol._idcol).values()
            if isinstance(c, type) and type(c).__name__ == "pybind11_type" and not hasattr(c, "__members__")]


@pytest.mark.parametrize("cls", _bound_classes(), ids=lambda c: c.__name__)
def test_objects_made_by_the_base_class_new_hold_nothing_readable(cls):
    """pybind11_object.__new__(Cls) reaches every class past the __new__
    that forbid_new installs: every property, repr and pickle of such an
    instance raises TypeError, never reads memory that nothing wrote.
    (SolverOptions, HertzModel and WarmStart hold zeros instead, which
    validation refuses or which are an empty warm start: the test above.)"""
    if cls in (idcol.SolverOptions, idcol.HertzModel, idcol.WarmStart):
        pytest.skip("zeroed storage (test_plain_data_made_by_new_without_init_holds_zeros_that_are_refused_or_empty)")
    base = cls.__mro__[-2]
    assert base.__name__ == "pybind11_object"
    obj = base.__new__(cls)
    names = [n for n, v in vars(cls).items() if isinstance(v, property)]
    assert names or cls is idcol.ContactPair
    for name in names + [n for n in ("__repr__", "__reduce__", "__getstate__", "__len__") if n in vars(cls)]:
        with pytest.raises(TypeError, match="__new__|cannot be pickled"):
            getattr(obj, name)() if name.startswith("__") else getattr(obj, name)
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        with pytest.raises(TypeError, match="__new__|cannot be pickled"):
            pickle.dumps(obj, protocol=protocol)


def test_plain_data_made_by_new_without_init_holds_zeros_that_are_refused_or_empty():
    """SolverOptions, HertzModel and WarmStart (plain C++ data with Python
    constructors) made by __new__ alone hold zeros, not uninitialised
    memory: validation refuses the options and the model, and the warm start
    is empty."""
    s = idcol.Sphere(1.0)
    o = idcol.SolverOptions.__new__(idcol.SolverOptions)
    with pytest.raises(ValueError, match="'tolerance' must be finite and > 0, got 0"):
        idcol.solve(s, s, np.eye(3), [3.0, 0.0, 0.0], options=o)
    h = idcol.HertzModel.__new__(idcol.HertzModel)
    with pytest.raises(ValueError, match="'stiffness' must be finite and > 0, got 0"):
        idcol.contact_wrench(idcol.solve(s, s, np.eye(3), [1.0, 0.0, 0.0]), model=h)
    w = idcol.WarmStart.__new__(idcol.WarmStart)
    assert not w.valid
    r = idcol.solve(s, s, np.eye(3), [3.0, 0.0, 0.0], warm_start=w)
    assert r.converged and r.alpha == 1.5 and w.valid


def test_objects_made_by_new_are_freed_without_harm():
    for cls in (idcol.Sphere, idcol.ContactPair, idcol.SmoothPolytope):
        for _ in range(1000):
            cls.__new__(cls)


@pytest.mark.parametrize("threads,idle_caller", [(1, False), (2, False), (2, True)])
def test_ctrl_c_stops_a_batch_long_before_its_end(threads, idle_caller):
    """SIGINT during a long batch: KeyboardInterrupt, and the batch stopped
    long before its end. The calling thread polls for it between its rows
    and, once they are done, while it waits for the other thread: with
    idle_caller its rows (the first half) are NaN poses, answered at once.

    How much of the batch ran is measured in CPU time, not wall time: the
    process's CPU time in the batch over what all its rows take (from the
    CPU time of a sample of them), so a loaded machine (ctest -j), which
    stretches the wall time, does not move it. The signal comes 0.5 s after
    the batch starts, about 0.1 of it on one thread; a batch that did not
    see the signal until its end would have run all of it (share 1)."""
    code = """
    import sys, time, numpy as np, idcol
    from _helpers import paper_shapes
    s = paper_shapes()
    n = 3 * 10**6  # about 8 s on one thread; with IDLE, 4 s on the second one
    rng = np.random.default_rng(0)
    R = np.repeat(np.eye(3)[None], n, 0); p = rng.uniform(-3, 3, (n, 3))
    # The CPU time a row takes, from a sample of the same poses on one thread.
    m = 20000
    c0 = time.process_time()
    idcol.solve_batch(s["Poly"], s["TC"], R[:m], p[:m], threads=1, derivatives=True, kinematics=False)
    per_row = (time.process_time() - c0) / m
    if IDLE:
        p[: n // 2] = np.nan
    rows = n // 2 if IDLE else n  # the rows that take time
    print("start", flush=True)
    c0 = time.process_time()
    try:
        idcol.solve_batch(s["Poly"], s["TC"], R, p, threads=THREADS, derivatives=True, kinematics=False)
        outcome = "finished"
    except KeyboardInterrupt:
        outcome = "interrupted"
    print("%s %.4f" % (outcome, (time.process_time() - c0) / (per_row * rows)), flush=True)
    """
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([os.path.dirname(os.path.dirname(idcol.__file__)), HERE,
                                         env.get("PYTHONPATH", "")])
    proc = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code).replace("THREADS", str(threads)).replace("IDLE", str(idle_caller))], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    assert proc.stdout.readline().strip() == "start"
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    outcome, share = out.split()
    assert outcome == "interrupted", (out, err[-2000:])
    # The share of the batch's work done when it stopped: well below 1.
    assert float(share) < 0.5, out


def test_threads_are_capped_at_the_cpus_this_process_may_use():
    """threads=10**6 runs (on at most the CPUs of the affinity mask) and gives
    the one-thread answer; no million OS threads."""
    code = """
    import os, threading, numpy as np, idcol
    import _helpers
    s = _helpers.paper_shapes()
    rng = np.random.default_rng(1)
    n = 3000
    R = np.repeat(np.eye(3)[None], n, 0); p = rng.uniform(-3, 3, (n, 3))
    a = idcol.solve_batch(s["SE"], s["TC"], R, p, threads=10**6)
    b = idcol.solve_batch(s["SE"], s["TC"], R, p, threads=1)
    assert np.array_equal(a.alpha, b.alpha)
    status = open("/proc/self/status").read()
    print("ok", len(os.sched_getaffinity(0)))
    """
    proc = run_python(code)
    assert proc.returncode == 0 and proc.stdout.startswith("ok"), proc.stderr[-2000:]


def test_a_huge_thread_count_does_not_start_a_thread_per_row(monkeypatch):
    """Counted from /proc: the peak number of threads of this process during
    a batch with threads=10**6 stays within the CPUs allowed plus a few."""
    import threading
    s = idcol.Sphere(1.0)
    n = 20000
    R = np.repeat(np.eye(3)[None], n, 0)
    p = np.random.default_rng(2).uniform(-3, 3, (n, 3))
    peak = [0]
    stop = threading.Event()

    def watch():
        while not stop.is_set():
            peak[0] = max(peak[0], len(os.listdir("/proc/self/task")))
            time.sleep(0.001)

    w = threading.Thread(target=watch)
    w.start()
    base = len(os.listdir("/proc/self/task"))
    try:
        for _ in range(5):
            idcol.solve_batch(s, s, R, p, threads=10**6, derivatives=True)
    finally:
        stop.set()
        w.join()
    assert peak[0] <= base + len(os.sched_getaffinity(0)) + 1, (peak[0], base)


def test_result_arrays_are_read_only():
    s = idcol.Sphere(1.0)
    out = idcol.solve_batch(s, s, np.eye(3)[None], [[3.0, 0.0, 0.0]], derivatives=True,
                            R_W1=np.eye(3), p_W1=np.zeros(3))
    for name in ("alpha", "x", "status", "iterations", "converged", "dalpha_dxi", "gap", "normal", "p1", "p2",
                 "normal_W", "p1_W", "p2_W", "dgap_dxi", "dnormal_dxi", "dp1_dxi", "dp2_dxi"):
        arr = getattr(out, name)
        assert not arr.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 0
    copy = np.array(out.alpha)
    copy[0] = 7.0
    assert out.alpha[0] != 7.0


def test_time_of_impact_batch_threads_are_capped_at_the_cpus():
    """threads=10**6 over 20,000 motions (cheap: two spheres moving apart)
    runs on at most the CPUs of the affinity mask, under a 4 GiB address
    space (a thread per row reserved 8 MiB of stack each and aborted there),
    with the one-thread answers; counted from /proc while it runs."""
    code = """
    import os, threading, time, numpy as np, idcol
    n = 20000
    a = idcol.Sphere(0.3)
    R = np.repeat(np.eye(3)[None], n, 0)
    p0 = np.column_stack([np.linspace(1.0, 2.0, n), np.zeros(n), np.zeros(n)])
    peak, stop = [0], threading.Event()
    def watch():
        while not stop.is_set():
            peak[0] = max(peak[0], len(os.listdir("/proc/self/task")))
            time.sleep(0.0005)
    base = len(os.listdir("/proc/self/task"))
    w = threading.Thread(target=watch); w.start()
    try:
        out = [idcol.time_of_impact_batch(a, a, R, p0, R, 2 * p0, threads=10**6) for _ in range(3)]
    finally:
        stop.set(); w.join()
    one = idcol.time_of_impact_batch(a, a, R, p0, R, 2 * p0, threads=1)
    assert all(np.array_equal(o.status, one.status) and np.array_equal(o.t, one.t) for o in out)
    assert (one.status == idcol.ToiStatus.NoImpact).all()
    print("ok", peak[0] - base - 1, len(os.sched_getaffinity(0)))
    """
    proc = run_python(code, limit_bytes=4 << 30)
    assert proc.returncode == 0 and proc.stdout.startswith("ok"), (proc.returncode, proc.stderr[-2000:])
    _, extra, cpus = proc.stdout.split()
    assert int(extra) <= int(cpus), proc.stdout


def test_time_of_impact_batch_runs_on_the_calling_thread_when_no_thread_can_start():
    """With no address space left for a thread's stack (8 MiB each), the
    chunks meant for other threads run on the calling thread: the same
    answers, no RuntimeError from the thread that could not start."""
    if len(os.sched_getaffinity(0)) < 2:
        pytest.skip("one CPU: the batch starts no thread")
    code = """
    import resource, numpy as np, idcol
    a = idcol.Sphere(0.3)
    n = 200
    R = np.repeat(np.eye(3)[None], n, 0)
    p0 = np.column_stack([np.linspace(1.0, 2.0, n), np.zeros(n), np.zeros(n)])
    one = idcol.time_of_impact_batch(a, a, R, p0, R, 2 * p0, threads=1)
    vm = int([l for l in open("/proc/self/status") if l.startswith("VmSize")][0].split()[1]) * 1024
    resource.setrlimit(resource.RLIMIT_AS, (vm + (4 << 20), vm + (4 << 20)))
    out = idcol.time_of_impact_batch(a, a, R, p0, R, 2 * p0, threads=0)
    assert np.array_equal(out.t, one.t) and np.array_equal(out.status, one.status)
    print("ok")
    """
    proc = run_python(code)
    assert proc.returncode == 0 and proc.stdout.startswith("ok"), (proc.returncode, proc.stderr[-2000:])
