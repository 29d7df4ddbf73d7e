#!/usr/bin/python3
"""Per-pair time and iteration distributions of one sweep results file.

usage: scripts/plot_run.py results/paper_table1.json [-o DIR]

Reads a results file of schema "idcol-harness-results" (written by
`idcol_harness run`) and writes, into DIR (default: the results file's
folder), files named after the results file:
  <stem>_times.png       one panel per pair: the distribution of the time per
                         solve of each pass (cold, warm, ...) from the stored
                         log histogram, log-x in us, median and p99 marked;
  <stem>_iterations.png  one panel per pair: the histogram of Newton
                         iterations per solve of each pass.
A file whose passes were not timed gets the iteration figure only (and a
message saying so). Any other schema: an error naming the file and its
schema, exit 2. Nothing is rerun; every number comes from the JSON file.

Time histograms (harness/src/stats/stats.cpp, LogHistogram::to_json): "bins" is a
sparse list of [index, count]; bin i holds the values v (in ns) with
log10_low + i / bins_per_decade <= log10(v) < log10_low + (i + 1) / bins_per_decade;
"under" / "over" count the values below / above the range, "nonfinite" the
NaNs and infinities. Iteration histograms map an iteration count (a string) to
its number of solves. The keys of the figures come from results/metrics.json
(harness_metrics.py), never typed here.
"""
import argparse
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker as mticker  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

import harness_metrics  # noqa: E402
from report_text import title_text  # noqa: E402

SCHEMA = "idcol-harness-results"
PASS_COLOR = {"cold": "C0", "warm": "C3"}
# A pass's time summary and its median and p99 (ns), and its iteration summary.
MEDIAN = harness_metrics.path("sweep", "{key}.time.median_us")
P99 = harness_metrics.path("sweep", "{key}.time.p99_us")
TIME = MEDIAN[:-1]
ITER_MEAN = harness_metrics.path("sweep", "{key}.iterations.mean")
ITER_MAX = harness_metrics.path("sweep", "{key}.iterations.max")
ITER = ITER_MEAN[:-1]


def at(obj, keys, default=None):
    """obj[k0][k1]...; default where a key is missing."""
    for k in keys:
        if not isinstance(obj, dict) or k not in obj:
            return default
        obj = obj[k]
    return obj


def pass_color(name, i):
    return PASS_COLOR.get(name, f"C{(i + 4) % 10}")


def pair_name(p):
    return title_text(f"{p.get('body1', '?')}-{p.get('body2', '?')}")


def pin_note(res):
    c = res.get("metadata", {}).get("pinned_cpu")
    if c is None:
        c = res.get("timing", {}).get("pinned_cpu")
    return f"one thread pinned to CPU {c}" if c is not None else "unpinned"


def grid(n):
    ncols = min(n, 5 if n > 8 else 4 if n > 4 else n)
    return ncols, math.ceil(n / ncols)


def time_hist(h):
    """Left bin edges (us, one more than bins) and counts of a LogHistogram's JSON, from its first to its
    last non-empty bin with the empty bins in between as zeros (drawn as gaps on the log axis)."""
    e0, per = h["log10_low"], h["bins_per_decade"]
    sparse = {int(i): int(c) for i, c in h["bins"]}
    if not sparse:
        return [], []
    first, last = min(sparse), max(sparse)
    edges = [10 ** (e0 + i / per) / 1e3 for i in range(first, last + 2)]
    return edges, [sparse.get(i, 0) for i in range(first, last + 1)]


def masked(fracs):
    return [f if f > 0 else float("nan") for f in fracs]


def poses_run(res):
    """The poses the file holds: "1,000,000 poses per pass" for the whole sweep (a single run, or shards
    merged), "10,000 poses per pass, shard 0/100 of 1,000,000" for a shard (shard.poses is [first, end) of
    the scene's sweep.poses)."""
    poses = res.get("sweep", {}).get("poses")
    sh = res.get("shard", {})
    span = sh.get("poses")
    if not isinstance(poses, int):
        return "? poses per pass"
    if not (isinstance(span, list) and len(span) == 2 and all(isinstance(x, int) for x in span)) or span == [0, poses]:
        return f"{poses:,} poses per pass"
    return f"{max(0, span[1] - span[0]):,} poses per pass, shard {sh.get('index', '?')}/{sh.get('count', '?')} of {poses:,}"


def header(res, stem, what, timed=True):
    md = res.get("metadata", {})
    sw = res.get("sweep", {})
    return (f"{title_text(stem)}{what}: {len(res['pairs'])} pairs x {title_text(poses_run(res))} "
            f"({title_text(sw.get('generator', '?'))} poses), passes {title_text(', '.join(res.get('passes', [])))}\n"
            f"git {title_text(str(md.get('git_revision', '?'))[:10])}, {title_text(md.get('cpu_model', '?'))}, "
            f"host {title_text(md.get('host', '?'))}, {pin_note(res) if timed else 'passes not timed'}")


def plot_times(res, stem, out_png):
    pairs = res["pairs"]
    ncols, nrows = grid(len(pairs))
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.3 * ncols, 2.7 * nrows + 1.6), sharex=True, squeeze=False,
                             constrained_layout=True)
    passes = res.get("passes") or sorted({k for p in pairs for k in p["passes"]})
    lo, hi = math.inf, 0.0
    notes = []
    for k, p in enumerate(pairs):
        ax = axes[k // ncols][k % ncols]
        stats = []
        for i, name in enumerate(passes):
            ps = p["passes"].get(name)
            t = at(ps, TIME)
            if t is None:
                continue
            h = t["histogram"]
            edges, counts = time_hist(h)
            total = h["count"]
            if not counts:
                continue
            fr = [c / total for c in counts]
            xs, ys = edges, masked(fr + fr[-1:])
            col = pass_color(name, i)
            ax.step(xs, ys, where="post", color=col, lw=0.9)
            # bin centres of the non-empty bins: single solves in the tail stay visible
            ax.plot([(xs[j] * xs[j + 1]) ** 0.5 for j, c in enumerate(counts) if c],
                    [f for f in fr if f > 0], ".", color=col, ms=2)
            ax.axvline(t[MEDIAN[-1]] / 1e3, color=col, ls="--", lw=0.9)
            ax.axvline(t[P99[-1]] / 1e3, color=col, ls=":", lw=1.2)
            lo, hi = min(lo, xs[0]), max(hi, xs[-1])
            out = h.get("under", 0) + h.get("over", 0) + h.get("nonfinite", 0)
            if out:
                notes.append(f"{pair_name(p)} {name}: {out} solve(s) outside the histogram's range")
            stats.append(f"{name} {t[MEDIAN[-1]] / 1e3:.2f} / {t[P99[-1]] / 1e3:.2f}")
        # the numbers go in the title, where they cannot cover the curves
        ax.set_title(pair_name(p) + "\n" + ", ".join(stats), fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.tick_params(labelsize=7)
    for k in range(len(pairs), nrows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    for ax in axes.flat:
        if lo < hi:
            ax.set_xlim(lo / 1.25, hi * 1.25)
        ax.xaxis.set_major_locator(mticker.LogLocator(numticks=10))
        ax.xaxis.set_major_formatter(mticker.FormatStrFormatter("%g"))
    for ax in axes[-1]:
        ax.set_xlabel("time per solve (us, log)", fontsize=8)
    for row in axes:
        row[0].set_ylabel("fraction of solves per bin\n(100 bins / decade, log)", fontsize=8)
    handles = []
    for i, name in enumerate(passes):
        col = pass_color(name, i)
        handles.append(Line2D([], [], color=col, lw=0.9, marker=".", ms=3, label=f"{name}: distribution"))
        handles.append(Line2D([], [], color=col, ls="--", lw=0.9, label=f"{name}: median"))
        handles.append(Line2D([], [], color=col, ls=":", lw=1.2, label=f"{name}: p99"))
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), fontsize=8, frameon=False) \
        if _has_outside() else fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8,
                                          frameon=False, bbox_to_anchor=(0.5, -0.04))
    fig.suptitle(header(res, stem, " time per solve (all solves, timer overhead subtracted)") +
                 "\npanel titles: median / p99 in us per pass", fontsize=9)
    fig.savefig(out_png, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return notes


def _has_outside():
    # loc="outside ..." for figure legends arrived in matplotlib 3.7.
    v = tuple(int(x) for x in matplotlib.__version__.split(".")[:2])
    return v >= (3, 7)


def plot_iterations(res, stem, out_png, timed):
    pairs = res["pairs"]
    ncols, nrows = grid(len(pairs))
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.3 * ncols, 2.7 * nrows + 1.6), sharex=True, squeeze=False,
                             constrained_layout=True)
    passes = res.get("passes") or sorted({k for p in pairs for k in p["passes"]})
    kmax = 0
    for p in pairs:
        for name in passes:
            it = at(p["passes"].get(name, {}), ITER)
            if it and it.get("histogram"):
                kmax = max(kmax, max(int(k) for k in it["histogram"]))
    for k, p in enumerate(pairs):
        ax = axes[k // ncols][k % ncols]
        stats = []
        for i, name in enumerate(passes):
            it = at(p["passes"].get(name, {}), ITER)
            if not it or not it.get("histogram"):
                continue
            hist = {int(a): int(b) for a, b in it["histogram"].items()}
            total = sum(hist.values())
            ks = list(range(min(hist), max(hist) + 1))
            fr = [hist.get(x, 0) / total for x in ks]
            col = pass_color(name, i)
            ax.plot(ks, masked(fr), drawstyle="steps-mid", color=col, lw=0.9)
            ax.plot([x for x, f in zip(ks, fr) if f > 0], [f for f in fr if f > 0], ".", color=col, ms=2.5)
            stats.append(f"{name} mean {it[ITER_MEAN[-1]]:.2f}, max {it[ITER_MAX[-1]]}")
        ax.set_title(pair_name(p) + "\n" + "; ".join(stats), fontsize=8)
        ax.set_yscale("log")
        # linear up to 10 iterations (where most solves are), logarithmic beyond (the tails)
        ax.set_xscale("symlog", linthresh=10, linscale=1.5)
        ax.set_xlim(-0.5, kmax * 1.1 + 1)
        ax.xaxis.set_major_locator(mticker.FixedLocator([t for t in (0, 2, 4, 6, 8, 10, 20, 50, 100, 200, 500)
                                                         if t <= kmax * 1.1 + 1]))
        ax.xaxis.set_major_formatter(mticker.FormatStrFormatter("%g"))
        ax.xaxis.set_minor_locator(mticker.NullLocator())
        ax.tick_params(labelsize=7)
    for k in range(len(pairs), nrows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("Newton iterations per solve (count;\nlinear to 10, log beyond)", fontsize=8)
    for row in axes:
        row[0].set_ylabel("fraction of solves (log)", fontsize=8)
    handles = [Line2D([], [], color=pass_color(n, i), marker=".", lw=0.9, label=n) for i, n in enumerate(passes)]
    if _has_outside():
        fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), fontsize=8, frameon=False)
    else:
        fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False,
                   bbox_to_anchor=(0.5, -0.04))
    fig.suptitle(header(res, stem, " Newton iterations per solve", timed) +
                 "\n(every Newton run of every restart and continuation stage counted)", fontsize=9)
    fig.savefig(out_png, dpi=100, bbox_inches="tight")
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results", help="a results file of schema idcol-harness-results")
    ap.add_argument("-o", "--outdir", default=None, help="output folder (default: the results file's folder)")
    a = ap.parse_args()
    try:
        with open(a.results) as f:
            res = json.load(f)
    except (OSError, ValueError) as e:
        print(f"{a.results}: cannot read: {e}", file=sys.stderr)
        return 2
    schema = res.get("schema") if isinstance(res, dict) else None
    if schema != SCHEMA:
        print(f"{a.results}: schema {schema!r}; plot_run.py reads only sweep results ({SCHEMA}, from "
              f"'idcol_harness run')", file=sys.stderr)
        return 2
    if not res.get("pairs"):
        print(f"{a.results}: no pairs, nothing to plot", file=sys.stderr)
        return 2
    outdir = a.outdir if a.outdir is not None else (os.path.dirname(a.results) or ".")
    os.makedirs(outdir, exist_ok=True)
    # Output names come from the results file's name, never from the scene's free-text name.
    stem = os.path.basename(a.results)
    stem = stem[:-5] if stem.endswith(".json") else stem
    timed = any(at(ps, TIME) is not None for p in res["pairs"] for ps in p["passes"].values())
    if timed:
        png = os.path.join(outdir, stem + "_times.png")
        for n in plot_times(res, stem, png):
            print(f"note: {n}")
        print(f"wrote {png}")
    else:
        print(f"{a.results}: no pass was timed (no passes.*.time), so no time figure; iterations only")
    png = os.path.join(outdir, stem + "_iterations.png")
    plot_iterations(res, stem, png, timed)
    print(f"wrote {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
