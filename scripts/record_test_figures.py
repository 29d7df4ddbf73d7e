#!/usr/bin/env python3
"""Runs the tests whose measured figures the documentation quotes and writes
those figures, with the run's revision and machine, into one results file.

A test records a figure with idcol::test::measured (baselines/tests/measured.hpp):
a gtest property, which `--gtest_output=json` keeps. This script runs each
binary of TESTS on its filter, reads the properties back and writes

    {"schema": "idcol-test-figures", "schema_version": 1,
     "metadata": {git_revision, git_dirty, date_utc, cpu_model, logical_cpus, command},
     "tests": {SUITE: {TEST: {KEY: value, ...}}}}

where a '/' in a key nests it (pair/method/figure) and each value is a
number. baselines/README.md quotes them through scripts/check_doc_figures.py
(`results/test_figures.json:tests.Dcol.SpheresMatchTheClosedFormAndTheSegmentPoint.worst_err_over_gap`).

    scripts/record_test_figures.py BUILD -o results/test_figures.json

BUILD is a build of this checkout (the file names the checkout's revision).

The file is written only when every test ran and passed and each test of
TESTS recorded a figure (a test that was skipped, or a binary without FCL,
libccd or Bullet, is an error naming it); it is written to a temporary
file and renamed, so a failed run leaves the old file as it was.
Exit status: 0 written; 1 a test failed, was skipped or recorded nothing;
2 bad command line.
"""
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# binary (under BUILD) -> the gtest filter of the tests whose figures are quoted.
TESTS = {
    "baselines/tests/idcol_dcol_tests": "Dcol.*",
    "baselines/tests/idcol_baselines_tests": ":".join([
        "PerramWertheim.AgreesWithIdcolOnExactEllipsoids",
        "Bisection.OverFclBooleanMatchesPerramWertheim",
        "SupportOracle.*",
        "Booleans.AgreeWithOracleOutsideToleranceBand",
        "FclDistance.*",
        "Penetration.*",
        "Bullet.*",
    ]),
}


def git(*args):
    p = subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)
    return p.stdout.strip() if p.returncode == 0 else None


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def number(text):
    try:
        return float(text)
    except ValueError:
        return text


def nest(into, key, value):
    *path, last = key.split("/")
    for k in path:
        into = into.setdefault(k, {})
    into[last] = value


def run_binary(binary, gtest_filter, tests):
    """Runs one binary and adds its tests' figures to `tests`; returns the
    problems (failed, skipped or silent tests)."""
    problems = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.json")
        p = subprocess.run([binary, f"--gtest_filter={gtest_filter}", f"--gtest_output=json:{out}"],
                           capture_output=True, text=True)
        if not os.path.exists(out):
            return [f"{binary}: no gtest report (exit {p.returncode}): {p.stderr.strip()[-500:]}"]
        with open(out) as f:
            report = json.load(f)
    reserved = {"name", "status", "result", "timestamp", "time", "classname", "failures", "file", "line",
                "value_param", "type_param"}
    for suite in report.get("testsuites", []):
        for t in suite.get("testsuite", []):
            name = f"{suite['name']}.{t['name']}"
            if t.get("failures"):
                problems.append(f"{name} failed")
            if t.get("result") == "SKIPPED" or t.get("status") == "NOTRUN":
                problems.append(f"{name} was skipped (a library this build lacks?)")
            figures = {k: v for k, v in t.items() if k not in reserved}
            # A test named on the filter must record a figure; a suite's
            # wildcard also runs tests that only assert.
            if not figures and name in gtest_filter.split(":"):
                problems.append(f"{name} recorded no figure")
            for k, v in sorted(figures.items()):
                nest(tests.setdefault(suite["name"], {}).setdefault(t["name"], {}), k, number(v))
    if p.returncode != 0 and not problems:
        problems.append(f"{binary} exited {p.returncode}")
    return problems


def main(argv):
    args = [a for a in argv if a not in ("-h", "--help")]
    if len(args) != len(argv) or len(args) != 3 or args[1] != "-o":
        print(__doc__.split("\n\n")[0] + "\n\nusage: scripts/record_test_figures.py BUILD -o OUT.json", file=sys.stderr)
        return 0 if len(args) != len(argv) else 2
    build, out = args[0], args[2]
    tests, problems = {}, []
    for rel, flt in TESTS.items():
        binary = os.path.join(build, rel)
        if not os.access(binary, os.X_OK):
            problems.append(f"{binary} is not built (cmake --build {build} --target {os.path.basename(rel)})")
            continue
        problems += run_binary(binary, flt, tests)
    if problems:
        for p in problems:
            print(f"record_test_figures: {p}", file=sys.stderr)
        print(f"record_test_figures: {out} not written", file=sys.stderr)
        return 1
    status = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)results")
    result = {
        "schema": "idcol-test-figures",
        "schema_version": 1,
        "metadata": {
            "git_revision": git("rev-parse", "HEAD") or "unknown",
            "git_dirty": bool(status) if status is not None else None,
            "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "cpu_model": cpu_model(),
            "logical_cpus": os.cpu_count(),
            "command": " ".join(["scripts/record_test_figures.py", *args]),
            "tests": TESTS,
        },
        "tests": tests,
    }
    d = os.path.dirname(os.path.abspath(out))
    fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(out)}.", dir=d)
    with os.fdopen(fd, "w") as f:
        json.dump(result, f, indent=1, sort_keys=True)
        f.write("\n")
    os.replace(tmp, out)
    n = sum(len(t) for t in tests.values())
    print(f"record_test_figures: {n} tests' figures into {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
