#!/usr/bin/python3
"""The history page in a real browser: `idcol_harness history show --html`
on a history file, opened by headless Chromium, which dumps the DOM it
rendered, takes a screenshot and logs the page's console. Passes when the
DOM holds one SVG plot (with its axes and at least one point) per metric
and entry that has a value in the history (counted here from the JSON
Lines, not from the page), the screenshot is a PNG of the window's size,
and the page logged no console message nor failed load. A control page
that logs an error must be caught, so that a silent log cannot pass.

    history_page.py IDCOL_HARNESS HISTORY.jsonl OUT_DIR

Exit 77 (ctest: skipped) when Chromium is not installed (scripts/setup.sh
installs Debian's `chromium`).
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

WIDTH, HEIGHT = 1300, 2200


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def browse(browser, page, *flags):
    """Runs headless Chromium on a local file; returns (stdout, stderr)."""
    with tempfile.TemporaryDirectory() as profile:
        cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--user-data-dir=" + profile,
               "--enable-logging=stderr", "--v=0", "--window-size=%d,%d" % (WIDTH, HEIGHT), *flags, "file://" + page]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=150)
        return p.stdout, p.stderr


def page_problems(stderr):
    """The lines of Chromium's log that the page caused: console messages
    (CONSOLE), script errors, loads that failed. Its own start-up noise (no
    D-Bus in a container) is not the page's."""
    return [l for l in stderr.splitlines() if re.search(r"CONSOLE|Uncaught|Failed to load|net::ERR_", l)]


def expected_plots(history):
    """Per series, the (entry, metric) pairs with a value at some commit."""
    series = {}
    with open(history) as f:
        for line in f:
            if not line.strip():
                continue
            r = json.loads(line)
            s = series.setdefault(r["series"], set())
            for entry, metrics in r["entries"].items():
                for metric, v in metrics.items():
                    if isinstance(v, (int, float)):
                        s.add((entry, metric))
    return sum(len(s) for s in series.values())


def main():
    harness, history, out = sys.argv[1:4]
    browser = chromium()
    if not browser:
        print("SKIP: Chromium is not installed (scripts/setup.sh installs Debian's chromium)")
        return 77
    os.makedirs(out, exist_ok=True)
    page = os.path.abspath(os.path.join(out, "history.html"))
    shot = os.path.abspath(os.path.join(out, "history.png"))
    subprocess.run([harness, "history", "show", history, "--html", page], check=True)

    # The detector sees a console error when there is one.
    control = os.path.join(out, "control.html")
    with open(control, "w") as f:
        f.write("<!DOCTYPE html><html><body><script>console.error('control error')</script></body></html>")
    _, err = browse(browser, os.path.abspath(control), "--dump-dom")
    if not page_problems(err):
        print("FAIL: the control page's console.error was not seen in Chromium's log; the check below would prove nothing")
        return 1

    dom, err = browse(browser, page, "--dump-dom")
    problems = page_problems(err)
    svgs = re.findall(r"<svg\b.*?</svg>", dom, flags=re.S)
    want = expected_plots(history)
    failures = []
    if want == 0:
        failures.append("the history %s has no metric to plot" % history)
    if len(svgs) != want:
        failures.append("the rendered DOM has %d <svg> plots, the history has %d metric-entry pairs" % (len(svgs), want))
    empty = [i for i, s in enumerate(svgs) if "<path" not in s or "<circle" not in s]
    if empty:
        failures.append("%d plots have no axes or no point (first: plot %d)" % (len(empty), empty[0]))
    if problems:
        failures.append("the page logged: " + " | ".join(problems[:5]))

    if os.path.exists(shot):
        os.remove(shot)
    _, err = browse(browser, page, "--screenshot=" + shot, "--hide-scrollbars")
    if not os.path.exists(shot):
        failures.append("no screenshot was written: " + err[-500:])
    else:
        with open(shot, "rb") as f:
            head = f.read(24)
        if head[:8] != b"\x89PNG\r\n\x1a\n":
            failures.append("the screenshot is not a PNG")
        else:
            w, h = struct.unpack(">II", head[16:24])
            if (w, h) != (WIDTH, HEIGHT):
                failures.append("the screenshot is %dx%d, not the window's %dx%d" % (w, h, WIDTH, HEIGHT))
    if failures:
        print("FAIL: " + "\n  ".join(failures))
        return 1
    print("ok: %d plots rendered, no console message; screenshot %s" % (len(svgs), shot))
    return 0


if __name__ == "__main__":
    sys.exit(main())
