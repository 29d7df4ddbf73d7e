#!/usr/bin/python3
"""Cost of idcol.solve_batch from Python against the C++ loop of solve(), and
its scaling from 1 to 2 threads, on 10^5 poses of the paper's sweep.

usage: scripts/bench_python_batch.py [--build build] [--reps 5] [-o results/python_batch.json]

  1. For each pair and mode (cold; warm in chains of 1024), `reps` times in
     turn: one run of the C++ loop of solve() (build/core/idcol_bench_batch,
     Google Benchmark, pinned by taskset -c 0), then idcol.solve_batch with
     threads=1 from this interpreter on the same poses (made here with NumPy
     by the same formula), pinned to CPU 0 by os.sched_setaffinity.
     Interleaving makes both see the same machine load; the overhead is the
     median of the per-repetition ratios.
  2. In turn, solve_batch with 1 thread (CPU 0) and 2 threads (CPUs 0, 1),
     each timed after one untimed call at that affinity: the speed-up is the
     median of the per-repetition ratios of wall times. (The first batch after
     the affinity changes waits 5-20 ms for the scheduler to move a new thread
     to the idle CPU; that is the machine's, not the module's, and the C++
     benchmark, which repeats back to back, does not see it either.)
  3. The per-call overhead of idcol.solve from Python: a Python loop of
     idcol.solve (ContactPair.solve when warm) over the same 10^5 poses,
     pinned to CPU 0, minus the C++ loop's time per pose (step 1); the
     difference is what one call costs beyond the solve (argument
     conversion, the result object).
  4. For reference: the C++ solve_batch with 1 and 2 threads (taskset -c 0,1).
  5. The SIMD lanes as a Python caller meets them: two ellipsoids on the
     same sweep, solve_batch with its default arguments (kinematics=True)
     and threads=1, pinned to CPU 0, with the lanes (the default) and
     without (IDCOL_SIMD=none: the loop inside the batch), interleaved;
     the speed-up is the median of the per-repetition ratios.
  The batches run with kinematics=False, so that both sides do the same work
  (the solve and nothing else).
Figures are in ns per pose, wall time and (one thread) CPU time, which time
spent descheduled on a shared machine does not inflate (the process's for
solve_batch; the calling thread's for the C++ loop and the Python loop). Writes a JSON file with the figures and the
machine's context, and prints a Markdown table.

Needs the module on the path: PYTHONPATH=build/python.
"""
import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time

import numpy as np

import idcol

N = 100000
CHAIN = 1024
S3 = 1.0 / math.sqrt(3.0)


def pairs():
    octa = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1],
                     [-1, -1, -1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]], float) * S3
    poly = idcol.SmoothPolytope(octa, np.array([1, 1, 1, 1, 5 / 3, 5 / 3, 5 / 3, 5 / 3]) * S3, beta=20.0)
    se = idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8)
    tc = idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20.0)
    sec = idcol.SuperellipticCylinder(R=1.0, h=2.0, n=8)
    return {"SE-Poly": (se, poly), "TC-SEC": (tc, sec)}


def paper_poses(a, b, n, dt=1e-4):
    (i1, o1), (i2, o2) = a.radii, b.radii
    rmin, rmax = 0.1 * min(i1, i2), 2.0 * max(o1, o2)
    t = np.arange(n) * dt
    tp = 2 * math.pi
    u = 0.5 * (1 + np.sin(tp * math.sqrt(2) * t))
    rad = np.cbrt(rmin ** 3 + (rmax ** 3 - rmin ** 3) * u)
    th = 0.5 * math.pi * np.sin(tp * math.sqrt(3) * t)
    ph = tp * math.sqrt(5) * t
    p = rad[:, None] * np.stack([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), np.sin(th)], axis=1)
    q = np.stack([np.sin(tp * math.sqrt(7) * t), np.cos(tp * math.sqrt(11) * t),
                  np.sin(tp * math.sqrt(13) * t), np.cos(tp * math.sqrt(17) * t)], axis=1)
    q /= np.linalg.norm(q, axis=1)[:, None]
    w, x, y, z = q.T
    R = np.empty((n, 3, 3))
    R[:, 0] = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1)
    R[:, 1] = np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=1)
    R[:, 2] = np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)
    return R, p


def cpp_bench(exe, cpus, filt, reps):
    cmd = ["taskset", "-c", cpus, exe, "--benchmark_filter=" + filt, "--benchmark_repetitions=%d" % reps,
           "--benchmark_format=json"]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    if not out.strip():
        raise SystemExit("no C++ benchmark matched: %s" % " ".join(cmd))
    runs = [b for b in json.loads(out)["benchmarks"] if b.get("run_type") == "iteration"]
    res = {}
    for b in runs:
        if "error_occurred" in b and b["error_occurred"]:
            raise SystemExit("C++ benchmark %s: %s" % (b["name"], b.get("error_message")))
        name = b["run_name"].split("/min_time")[0]
        res.setdefault(name, {"wall": [], "cpu": []})
        res[name]["wall"].append(b["real_time"] * 1e6 / N)  # ms per pass -> ns per pose
        res[name]["cpu"].append(b["cpu_time"] * 1e6 / N)
    return " ".join(cmd), {k: {m: statistics.median(v) for m, v in d.items()} for k, d in res.items()}


def time_python(fn, reps):
    """Median wall, calling-thread CPU and whole-process CPU (every thread) time, ns."""
    wall, cpu, proc = [], [], []
    for _ in range(reps):
        w0, c0, p0 = time.perf_counter(), time.thread_time(), time.process_time()
        fn()
        cpu.append((time.thread_time() - c0) * 1e9)
        proc.append((time.process_time() - p0) * 1e9)
        wall.append((time.perf_counter() - w0) * 1e9)
    return statistics.median(wall), statistics.median(cpu), statistics.median(proc)


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("-o", "--out", default=None, help="JSON file for the figures")
    args = ap.parse_args()
    exe = os.path.join(args.build, "core", "idcol_bench_batch")
    load_before = os.getloadavg()

    cmd2, cpp2 = cpp_bench(exe, "0,1", "batch", args.reps)

    rows = []
    for name, (a, b) in pairs().items():
        R, p = paper_poses(a, b, N)
        for warm in (False, True):
            mode = "warm" if warm else "cold"
            key = "%s/%s" % (mode, name)
            # Check before timing: every pose converges, and threads change nothing.
            one = idcol.solve_batch(a, b, R, p, warm_start=warm, threads=1, warm_chain=CHAIN, kinematics=False)
            two = idcol.solve_batch(a, b, R, p, warm_start=warm, threads=2, warm_chain=CHAIN, kinematics=False)
            if not one.converged.all() or not np.array_equal(one.alpha, two.alpha):
                raise SystemExit("%s: batch did not converge everywhere or threads changed the answer" % key)

            def batch(threads):
                return lambda: idcol.solve_batch(a, b, R, p, warm_start=warm, threads=threads, warm_chain=CHAIN,
                                               kinematics=False)

            # Interleaved: each repetition times the C++ loop (one Google
            # Benchmark run, pinned to CPU 0) and then this module's batch on
            # the same CPU, so both see the same machine load; the overhead is
            # the median of the per-repetition ratios.
            loop_cpu, loop_wall, py_cpu, py_wall, r_cpu, r_wall = [], [], [], [], [], []
            for _ in range(args.reps):
                cmd1, c = cpp_bench(exe, "0", "^%s/loop/" % key, 1)
                c = c[key + "/loop"]
                os.sched_setaffinity(0, {0})
                batch(1)()  # untimed, as Google Benchmark warms up before it times
                # Process CPU time, as for the 2-thread runs below (with one
                # thread, the same as the calling thread's).
                w, _, cpu = time_python(batch(1), 1)
                loop_cpu.append(c["cpu"])
                loop_wall.append(c["wall"])
                py_cpu.append(cpu / N)
                py_wall.append(w / N)
                r_cpu.append(cpu / N / c["cpu"])
                r_wall.append(w / N / c["wall"])
            # 1 against 2 threads, interleaved the same way.
            w1, w2, p2 = [], [], []
            for _ in range(args.reps):
                # One untimed call after each change of affinity: the first
                # batch after it pays for the scheduler placing the new
                # threads (5-20 ms on this VM), which the C++ benchmark's
                # back-to-back repetitions do not see either.
                os.sched_setaffinity(0, {0})
                batch(1)()
                w1.append(time_python(batch(1), 1)[0])
                os.sched_setaffinity(0, {0, 1})
                batch(2)()
                t = time_python(batch(2), 1)
                w2.append(t[0])
                p2.append(t[2])
            speedup = statistics.median([x / y for x, y in zip(w1, w2)])
            # A Python loop of single solves over the same poses: the per-call
            # overhead of solve from Python against the C++ loop.
            loop_n = N
            os.sched_setaffinity(0, {0})
            if warm:
                def py_loop():
                    pair = idcol.ContactPair(a, b)
                    for k in range(loop_n):
                        if k % CHAIN == 0:
                            pair.reset_warm_start()
                        pair.solve(R[k], p[k])
            else:
                def py_loop():
                    for k in range(loop_n):
                        idcol.solve(a, b, R[k], p[k])
            pyl = time_python(py_loop, 3)
            os.sched_setaffinity(0, {0, 1})
            med = statistics.median
            rows.append({
                "pair": name, "mode": mode,
                "cpp_loop_ns": {"cpu": med(loop_cpu), "wall": med(loop_wall)},
                "py_batch1_ns": {"cpu": med(py_cpu), "wall": med(py_wall)},
                "overhead_vs_cpp_loop_cpu": med(r_cpu) - 1.0,
                "overhead_vs_cpp_loop_wall": med(r_wall) - 1.0,
                "py_batch1_wall_ns_scaling_run": med(w1) / N,
                "py_batch2_ns": {"wall": med(w2) / N, "process_cpu": med(p2) / N},
                "speedup_2_threads_wall": speedup,
                "cpp_batch1_ns": cpp2[key + "/batch/threads:1"], "cpp_batch2_ns": cpp2[key + "/batch/threads:2"],
                "py_loop_ns": {"wall": pyl[0] / loop_n, "cpu": pyl[1] / loop_n},
                "solve_call_overhead_ns": {"wall": pyl[0] / loop_n - med(loop_wall),
                                           "cpu": pyl[1] / loop_n - med(loop_cpu)},
            })

    print("| pair | mode | C++ loop of solve, 1 thr (cpu / wall) | Python solve_batch, 1 thr (cpu / wall) "
          "| overhead (cpu / wall) | Python solve_batch, 2 thr (wall / cpu of both) | speed-up 1 -> 2 thr (wall) "
          "| C++ solve_batch 1 / 2 thr (wall) | Python loop of idcol.solve (wall) "
          "| per-call overhead of solve from Python (cpu / wall) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %s | %.0f / %.0f | %.0f / %.0f | %+.1f%% / %+.1f%% | %.0f / %.0f | %.2fx | %.0f / %.0f | %.0f "
              "| %.0f / %.0f |" % (
            r["pair"], r["mode"], r["cpp_loop_ns"]["cpu"], r["cpp_loop_ns"]["wall"],
            r["py_batch1_ns"]["cpu"], r["py_batch1_ns"]["wall"],
            100 * r["overhead_vs_cpp_loop_cpu"], 100 * r["overhead_vs_cpp_loop_wall"],
            r["py_batch2_ns"]["wall"], r["py_batch2_ns"]["process_cpu"], r["speedup_2_threads_wall"],
            r["cpp_batch1_ns"]["wall"], r["cpp_batch2_ns"]["wall"], r["py_loop_ns"]["wall"],
            r["solve_call_overhead_ns"]["cpu"], r["solve_call_overhead_ns"]["wall"]))
    print("(ns per pose; medians over %d interleaved repetitions of 10^5 poses; overhead and speed-up are medians "
          "of per-repetition ratios; Python loop: the same 10^5 poses, 3 runs)" % args.reps)

    # 5. The lanes from Python, default arguments (kinematics included).
    e1 = idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=1)
    e2 = idcol.Superellipsoid(a=1.2, b=0.3, c=0.7, n=1)
    Re, pe = paper_poses(e1, e2, N)
    os.sched_setaffinity(0, {0})
    lanes = []
    for warm in (False, True):
        def ell():
            return idcol.solve_batch(e1, e2, Re, pe, warm_start=warm, threads=1)
        with_l, without, ratio = [], [], []
        saved = os.environ.get("IDCOL_SIMD")
        try:
            for _ in range(args.reps):
                os.environ.pop("IDCOL_SIMD", None)
                ell()
                a = time_python(ell, 1)[0]
                os.environ["IDCOL_SIMD"] = "none"
                ell()
                b = time_python(ell, 1)[0]
                with_l.append(a / N)
                without.append(b / N)
                ratio.append(b / a)
        finally:
            if saved is None:
                os.environ.pop("IDCOL_SIMD", None)
            else:
                os.environ["IDCOL_SIMD"] = saved
        lanes.append({"pair": "Ellip-Ellip", "mode": "warm" if warm else "cold", "kinematics": True,
                      "lanes_ns": statistics.median(with_l), "loop_in_batch_ns": statistics.median(without),
                      "speedup": statistics.median(ratio)})
    os.sched_setaffinity(0, {0, 1})
    print()
    print("| pair | mode | solve_batch, lanes (ns/pose) | solve_batch, IDCOL_SIMD=none (ns/pose) | speed-up |")
    print("|---|---|---|---|---|")
    for r in lanes:
        print("| %s | %s | %.0f | %.0f | %.2fx |" % (r["pair"], r["mode"], r["lanes_ns"], r["loop_in_batch_ns"], r["speedup"]))
    print("(default arguments: kinematics=True; threads=1, CPU 0; warm chains of 1024)")
    load_after = os.getloadavg()
    print("load average before %.2f, after %.2f (%d logical CPUs)" % (load_before[0], load_after[0], os.cpu_count()))

    if args.out:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        # Dirty: a tracked file outside results/ differs (a regeneration
        # rewrites results files in turn; they are outputs, not code).
        dirty = bool(subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)results"],
                                    capture_output=True, text=True).stdout.strip())
        doc = {"schema": "idcol-python-batch-bench", "version": 2,
               "metadata": {"date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                            "git_revision": rev, "git_dirty": dirty, "cpu_model": cpu_model(),
                            "logical_cpus": os.cpu_count(), "python": sys.version.split()[0],
                            "numpy": np.__version__, "idcol": getattr(idcol, "__version__", "?"),
                            "load_average_before": load_before, "load_average_after": load_after,
                            "command": " ".join(sys.argv), "cpp_commands": [cmd1 + "  (per repetition, per pair and mode)", cmd2],
                            "poses": N, "repetitions": args.reps, "warm_chain": CHAIN},
               "rows": rows, "lanes": lanes}
        tmp = args.out + ".tmp"
        with open(tmp, "w") as f:
            json.dump(doc, f, indent=1)
        os.replace(tmp, args.out)
        print("wrote", args.out)


if __name__ == "__main__":
    main()
