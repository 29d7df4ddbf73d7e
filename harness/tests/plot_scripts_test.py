#!/usr/bin/python3
"""The plot scripts (scripts/plot_run.py, scripts/plot_smoothing.py) on
results files edited by hand or cut to a shard: what they write into
Markdown and into figure titles comes from the file, escaped
(scripts/report_text.py), and says what was run. Each test reads the
checked-in results (results/) and writes into a temporary folder only.

    plot_scripts_test.py SOURCE_DIR

Exit 77 (ctest: skipped) when /usr/bin/python3 has no matplotlib.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

SRC = os.path.abspath(sys.argv.pop(1) if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPTS = os.path.join(SRC, "scripts")
RESULTS = os.path.join(SRC, "results")
sys.path.insert(0, SCRIPTS)

try:
    import matplotlib  # noqa: F401
except ImportError:
    print("SKIP: /usr/bin/python3 has no matplotlib (scripts/setup.sh installs python3-matplotlib)")
    sys.exit(77)

import report_text  # noqa: E402

HOSTILE = "x\n| y\u202ez\x1b[31m<b>`$q$"


def load(name):
    with open(os.path.join(RESULTS, name)) as f:
        return json.load(f)


def run(script, *args):
    return subprocess.run([sys.executable, os.path.join(SCRIPTS, script), *args], capture_output=True, text=True,
                          timeout=300)


class Escapes(unittest.TestCase):
    def test_text_as_the_harness_escapes_it(self):
        self.assertEqual(report_text.escaped("Poly-Ellip (cut)"), "Poly-Ellip (cut)")
        self.assertEqual(report_text.escaped("a\nb\x00c\u202ed\\e\u00fc"), "a\\nb\\x00c\\u202Ed\\\\e\u00fc")
        self.assertEqual(report_text.md_text("a|b<i>"), "a\\|b&lt;i>")
        self.assertEqual(report_text.md_text("x < 1, </i>"), "x < 1, &lt;/i>")
        self.assertEqual(report_text.md_code("a`b|c\\d"), "``a`b\\|c\\d``")
        self.assertEqual(report_text.title_text("$x$\n"), "\\$x\\$\\n")


class SmoothingMarkdown(unittest.TestCase):
    def test_hand_edited_names_neither_break_nor_hide_the_tables(self):
        import plot_smoothing
        res = load("smoothing_cone.json")
        res["name"] = HOSTILE
        res["failures_file"] = "f`|.json"
        res["points"][0] = {"value": 1.5, "valid": False, "invalid_reason": "bad: " + HOSTILE}
        md = plot_smoothing.table(res)
        head = md.splitlines()[0]
        self.assertTrue(head.startswith("### x\\n\\| y\\u202Ez\\x1B[31m&lt;b>`$q$ ("), head)
        for raw in ("\u202e", "\x1b", "<b>", "x\n"):
            self.assertNotIn(raw, md)
        invalid = [line for line in md.splitlines() if "invalid:" in line]
        self.assertEqual(len(invalid), 1, md)
        self.assertIn("``f`\\|.json``", md)


def png_size(path):
    """Width and height of a PNG, from its IHDR chunk."""
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


class SmoothingRecommendation(unittest.TestCase):
    def test_the_threshold_is_the_one_the_results_file_records(self):
        import plot_smoothing
        res = load("smoothing_cone.json")

        def recommendation():
            return [line for line in plot_smoothing.table(res).splitlines() if line.startswith("Recommendation")][0]
        # A file made before the threshold was a scene option has no
        # recommend_error_below: 1 %, as it was then. (The checked-in file
        # records its threshold, 1 % too; the test removes it to read as an
        # old file.)
        self.assertEqual(res.get("recommend_error_below", 0.01), 0.01)
        res.pop("recommend_error_below", None)
        self.assertIn("relative error < 1 % and", recommendation())
        self.assertIn("**beta = 50**", recommendation())
        res["recommend_error_below"] = 0.05
        self.assertIn("relative error < 5 % and", recommendation())
        self.assertIn("**beta = 10**", recommendation())
        # The figure, from the script as a user runs it: larger and sharper than the 880 x 800 pixels at
        # 80 dpi it was.
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.join(tmp, "smoothing_cone.json")
            with open(src, "w") as f:
                json.dump(res, f)
            r = run("plot_smoothing.py", src, "-o", tmp, "--md", os.path.join(tmp, "s.md"))
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertGreaterEqual(png_size(os.path.join(tmp, "smoothing_cone.png")), (2000, 3000))
            with open(os.path.join(tmp, "s.md")) as f:
                self.assertIn("relative error < 5 % and", f.read())


class RunFigures(unittest.TestCase):
    def test_a_shard_is_titled_with_the_poses_it_ran(self):
        # A 1/100 shard of Table 1 was titled "1,000,000 poses per pass".
        import plot_run
        res = load("paper_table1.json")
        whole = plot_run.header(res, "t", " x")
        self.assertIn("10 pairs x 1,000,000 poses per pass (paper poses)", whole)
        res["shard"] = {"index": 3, "count": 100, "chains": [3, 4], "poses": [30000, 40000]}
        self.assertIn("10 pairs x 10,000 poses per pass, shard 3/100 of 1,000,000 (paper poses)", plot_run.header(res, "t", " x"))
        res["shard"]["merged_from"] = []
        res["shard"].update({"index": 0, "count": 1, "poses": [0, 1000000]})
        self.assertEqual(plot_run.header(res, "t", " x"), whole)

    def test_a_name_that_reads_as_mathtext_is_drawn_as_text(self):
        # "$\\nosuchcommand$" once stopped plot_run.py with matplotlib's "Unknown symbol".
        res = load("uniform_so3.json")
        res["pairs"][0]["body1"] = "$\\nosuchcommand$"
        res["metadata"]["cpu_model"] = HOSTILE
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.join(tmp, "u.json")
            with open(src, "w") as f:
                json.dump(res, f)
            r = run("plot_run.py", src, "-o", tmp)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue(os.path.getsize(os.path.join(tmp, "u_iterations.png")) > 1000)


if __name__ == "__main__":
    unittest.main(verbosity=2)
