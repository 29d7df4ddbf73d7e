#!/usr/bin/python3
"""Figures and a summary table for the smoothing study, from its results files only.

usage: scripts/plot_smoothing.py results/smoothing_*.json [-o results/] [--md results/smoothing.md]
                                 [--combined results/smoothing_error_vs_time.png]

For each results file (one family) writes <outdir>/<results file's stem>.png
(results/smoothing_cone.json -> <outdir>/smoothing_cone.png; the scene's
`name` is never used in a path) with four panels:
  (a) alpha* relative error (p99, max) and radial gap (Hausdorff upper-bound
      estimate) against median time per solve, one point per parameter value,
      cold (circles) and warm (triangles) at the same error;
  (b) iterations (cold and warm mean, cold p99) against the parameter;
  (c) conditioning sigma_min/sigma_max of the KKT Jacobian (p50, p01, min)
      against the parameter;
  (d) smoothness: IFT first-order prediction error relative to the change
      (alpha* and normal, p99) and the largest normal jump per unit step.
With --combined, also one figure of alpha* relative error (p99) against the
median cold time per solve, one line per family.
Failure-record files (schema idcol-harness-failures, *.failures.json) that a
shell glob picks up are skipped; any other schema is an error (exit 2).
The recommendation rule: the smallest parameter value whose alpha* error
stays under the threshold at p99 and whose cold and warm passes converged on
every pose. The threshold is the scene's [study] recommend_error_below
(default 0.01, 1 %), as the results file records it.
Nothing is rerun; the numbers come from the JSON files.
"""
import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker as mticker  # noqa: E402

import harness_metrics  # noqa: E402
from report_text import md_code, md_text, title_text  # noqa: E402

# The keys of the figures, from the harness's declared metrics (never typed
# here): the accuracy pass and its alpha* error, a timing pass's converged
# fraction and iterations, the geometry's radial gap and Hausdorff bound, and
# the smoothness's jumps per step.
ACC = harness_metrics.where("smoothing", "accuracy.alpha_rel_error.p99")
AERR = harness_metrics.key("smoothing", "accuracy.alpha_rel_error.p99")
CONV = harness_metrics.key("smoothing", "{key}.converged_fraction")
ITERS = harness_metrics.key("smoothing", "{key}.iterations.mean")
GAP = harness_metrics.path("smoothing", "geometry.radial_gap_max_rel")
HAUSDORFF = harness_metrics.path("smoothing", "geometry.hausdorff_lower_rel")
SMOOTHNESS = harness_metrics.path("smoothing", "smoothness.normal_jump_per_step.p99")[0]
NJUMP = harness_metrics.key("smoothing", "smoothness.normal_jump_per_step.p99")
AJUMP = harness_metrics.key("smoothing", "smoothness.alpha_jump_rel_per_step.p99")


def at(obj, keys):
    for k in keys:
        obj = obj[k]
    return obj


def valid_points(res):
    return [p for p in res["points"] if p.get("valid")]


def cold_pass_converged_fraction(p):
    # From the status counts: results made at git 9ab679f stored a wrong
    # cold_accuracy_pass.converged_fraction (0, a status-key typo since fixed).
    c = p["cold_accuracy_pass"]
    return c["statuses"].get("converged", 0) / c["poses"]


def recommend(res):
    for p in valid_points(res):
        e = p[ACC][AERR].get("p99")
        t = p["timing"]
        if e is not None and e < threshold(res) and t["cold"][CONV] == 1.0 and t["warm"][CONV] == 1.0 \
                and cold_pass_converged_fraction(p) == 1.0:
            return p
    return None


# Canonical order of the families in figures and tables, whatever order a
# shell glob hands the files in.
FAMILY_ORDER = ("smooth_polytope", "smooth_truncated_cone", "superellipsoid", "superelliptic_cylinder")
FAMILY_LABEL = {"smooth_polytope": "polytope (Poly)", "smooth_truncated_cone": "truncated cone (TC)",
                "superellipsoid": "superellipsoid (SE)", "superelliptic_cylinder": "cylinder (SEC)"}
PARAM_UNIT = {"beta": "beta (smoothing sharpness, dimensionless)", "n": "n (exponent, dimensionless)"}


def par_label(par):
    return PARAM_UNIT.get(par, f"{par} (dimensionless)")


def pin_note(res):
    """"one thread pinned to CPU k" if every timed pass of the file was pinned, else "unpinned".

    Smoothing results record the pin per grid point (points[i].timing.pinned_cpu);
    sweep results record it in metadata.pinned_cpu. Both are read."""
    pins = [p["timing"].get("pinned_cpu") for p in valid_points(res)]
    meta = res.get("metadata", {}).get("pinned_cpu")
    if meta is not None and not pins:
        pins = [meta]
    # An unpinned run records null (or a negative CPU, as older files do).
    pinned = [c for c in pins if c is not None and c >= 0]
    if pins and len(pinned) == len(pins):
        cpus = sorted(set(pinned))
        return "one thread pinned to CPU " + ", ".join(str(c) for c in cpus)
    if pinned:
        return f"pinned on {len(pinned)} of {len(pins)} grid points"
    return "unpinned"


def place_labels(fig, ax, series, fontsize=7):
    """Value labels that overlap neither each other nor the plotted points and lines.

    series: (xs, ys, labels, color) per line. Each label tries eight offsets
    around its point and takes the first one that is free; a label with no
    free place is left off. Returns how many were left off."""
    fig.canvas.draw()  # settles the layout and the limits, so data -> pixels is final
    fig.set_layout_engine("none")
    px = fig.dpi / 72.0
    obstacles = []
    for xs, ys, _, _ in series:
        pts = ax.transData.transform(list(zip(xs, ys)))
        for (x0, y0), (x1, y1) in zip(pts[:-1], pts[1:]):
            for t in [i / 8 for i in range(9)]:
                x, y = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
                obstacles.append((x - 3, y - 3, x + 3, y + 3))
        for x, y in pts:
            obstacles.append((x - 4, y - 4, x + 4, y + 4))
    box = ax.get_window_extent()
    left_off = 0
    for xs, ys, labels, color in series:
        for (x, y), lab, xd, yd in zip(ax.transData.transform(list(zip(xs, ys))), labels, xs, ys):
            if not lab:
                continue
            w, h = 0.62 * fontsize * px * len(lab) + 2, fontsize * px + 2
            for dx, dy in ((6, 3), (-6 - w, 3), (6, -3 - h), (-6 - w, -3 - h), (-w / 2, 6), (-w / 2, -6 - h),
                           (8, -h / 2), (-8 - w, -h / 2)):
                r = (x + dx, y + dy, x + dx + w, y + dy + h)
                inside = r[0] >= box.x0 and r[2] <= box.x1 and r[1] >= box.y0 and r[3] <= box.y1
                if inside and not any(r[0] < o[2] and o[0] < r[2] and r[1] < o[3] and o[1] < r[3] for o in obstacles):
                    obstacles.append(r)
                    # offset in points from the data point: stays right at any savefig dpi
                    ax.annotate(lab, (xd, yd), xytext=(dx / px, dy / px), textcoords="offset points",
                                fontsize=fontsize, color=color, va="bottom", ha="left")
                    break
            else:
                left_off += 1
    return left_off


FONT = 10      # axis labels and legends of the figures
DPI = 150      # pixels per inch of the PNGs (14 x 21 in: 2100 x 3150 px per family)


def legend_below(ax, ncol=1):
    ax.legend(fontsize=FONT - 1, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=ncol, frameon=False)


def threshold(res):
    """The recommendation's bound on the alpha* p99 relative error: the scene's [study]
    recommend_error_below as the results file records it (files made before it was a scene option: 0.01)."""
    t = res.get("recommend_error_below", 0.01)
    return t if isinstance(t, (int, float)) and not isinstance(t, bool) and 0 < t < 1 else 0.01


def percent(t):
    return f"{100 * t:g} %"


def log_axis(ax, axis, label):
    """A log axis with plain numbers at 1, 2, 5 x 10^k (1.5, 3, 4, 6, 8 too where it spans under a decade,
    every half step where it spans under a factor 3, only 10^k where it spans more than 3 decades), no
    minor labels to crowd them. Call after plotting."""
    lo, hi = ax.get_xlim() if axis == "x" else ax.get_ylim()
    span = hi / lo
    subs = ([k / 10 for k in range(10, 100, 5)] if span < 3 else (1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0) if span < 10
            else (1.0, 2.0, 5.0) if span < 1000 else (1.0,))
    a = ax.xaxis if axis == "x" else ax.yaxis
    a.set_major_locator(mticker.LogLocator(subs=subs))
    a.set_major_formatter(mticker.FormatStrFormatter("%g") if span < 1e4 else mticker.LogFormatterSciNotation())
    a.set_minor_formatter(mticker.NullFormatter())
    (ax.set_xlabel if axis == "x" else ax.set_ylabel)(label, fontsize=FONT)


def over_grid(ax, res, ylabel, title, ylog=True):
    """An axes whose x is the grid's parameter (log), its labels and title."""
    ax.set_xscale("log")
    if ylog:
        ax.set_yscale("log")
        log_axis(ax, "y", ylabel)
    else:
        ax.set_ylabel(ylabel, fontsize=FONT)
    log_axis(ax, "x", par_label(res["parameter"]) + ", log")
    ax.set_title(title, fontsize=FONT + 1)


def panel_error(ax, res, pts, v):
    """(a) The alpha* p99 relative error against the exact body over the grid, and the threshold."""
    ax.plot(v, [p[ACC][AERR]["p99"] for p in pts], "o-", color="C0", ms=6, label="alpha* relative error p99 (cold accuracy pass)")
    ax.axhline(threshold(res), color="grey", lw=1, ls="-.", label=f"{percent(threshold(res))} threshold (the recommendation's)")
    over_grid(ax, res, "relative error (dimensionless, log)", "(a) error against the exact body")
    legend_below(ax)


def panel_error_ratios(ax, res, pts, v):
    """(b) The other measures of the error as multiples of the alpha* p99 error: the max, the radial gap and
    the Hausdorff lower bound (relative to the outer radius), which lie too close to it on (a)'s log axis."""
    e99 = [p[ACC][AERR]["p99"] for p in pts]
    ratio = lambda xs: [x / e if e else float("nan") for x, e in zip(xs, e99)]  # noqa: E731
    ax.plot(v, ratio([p[ACC][AERR]["max"] for p in pts]), "x-", color="C1", ms=7, mew=1.5, label="alpha* relative error max")
    ax.plot(v, ratio([at(p, GAP) for p in pts]), "s--", color="C2", ms=5, label="radial gap / outer radius (upper estimate)")
    ax.plot(v, ratio([at(p, HAUSDORFF) for p in pts]), "v:", color="C4", ms=6, label="Hausdorff lower bound / outer radius")
    over_grid(ax, res, "multiple of the alpha* p99 error of (a) (linear; 1: equal)", "(b) the other error measures against (a)'s",
              ylog=False)
    legend_below(ax)


def panel_time(ax, res, pts, v):
    """(c) Time per solve over the grid: cold and warm medians, the cold p01-p99 band over the poses."""
    t = {k: [p["timing"]["cold"]["time_ns"][k] / 1e3 for p in pts] for k in ("p01", "p50", "p99")}
    ax.fill_between(v, t["p01"], t["p99"], color="C0", alpha=0.15, lw=0, label="cold, p01 to p99 over the poses")
    ax.plot(v, t["p50"], "o-", color="C0", label="cold median")
    ax.plot(v, [p["timing"]["warm"]["time_ns"]["p50"] / 1e3 for p in pts], "^-", color="C3", label="warm median")
    over_grid(ax, res, f"time per solve (us, log), {pin_note(res)}",
              "(c) run time (one run's medians: compare their order, not values across runs)")
    legend_below(ax)


def panel_tradeoff(ax, res, pts, v):
    """(d) The trade-off: alpha* p99 error against the median time, cold (labelled with the parameter) and
    warm. Returns the labels' series, placed once the layout is final."""
    e99 = [p[ACC][AERR]["p99"] for p in pts]
    tc = [p["timing"]["cold"]["time_ns"]["p50"] / 1e3 for p in pts]
    tw = [p["timing"]["warm"]["time_ns"]["p50"] / 1e3 for p in pts]
    ax.plot(tc, e99, "o-", color="C0", ms=6, label="at the cold median time")
    ax.plot(tw, e99, "^--", color="C3", ms=6, label="at the warm median time (the same answers)")
    ax.axhline(threshold(res), color="grey", lw=1, ls="-.", label=f"{percent(threshold(res))} threshold")
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_axis(ax, "x", f"median time per solve (us, log), {pin_note(res)}")
    log_axis(ax, "y", "alpha* relative error p99 (dimensionless, log)")
    ax.set_title(f"(d) error against time (point labels: {title_text(res['parameter'])})", fontsize=FONT + 1)
    legend_below(ax)
    # The warm series unlabelled: its points and line are obstacles the labels keep clear of.
    return [(tc, e99, [f"{x:g}" for x in v], "C0"), (tw, e99, [""] * len(v), "C3")]


def panel_iterations(ax, res, pts, v):
    ax.plot(v, [p["timing"]["cold"][ITERS]["mean"] for p in pts], "o-", label="cold mean")
    ax.plot(v, [p["timing"]["cold"][ITERS]["p99"] for p in pts], "s:", label="cold p99")
    ax.plot(v, [p["timing"]["warm"][ITERS]["mean"] for p in pts], "^-", label="warm mean")
    over_grid(ax, res, "Newton iterations per solve (count)", "(e) iterations", ylog=False)
    legend_below(ax, ncol=3)


def panel_conditioning(ax, res, pts, v):
    """(f) sigma_min / sigma_max: median and min, the 1st percentile drawn only where it is not within 10 %
    of the min (on a log axis the two lines would lie on each other)."""
    rc = [p["conditioning"]["rcond_svd"] for p in pts]
    close = all(r["min"] > 0 and r["p01"] <= 1.1 * r["min"] for r in rc)
    ax.plot(v, [r["p50"] for r in rc], "o-", label="median")
    if not close:
        ax.plot(v, [r["p01"] for r in rc], "s--", label="1st percentile")
    ax.plot(v, [r["min"] for r in rc], "v:", label="min" + (" (the 1st percentile within 10 % of it at every value)" if close else ""))
    over_grid(ax, res, "sigma_min / sigma_max of J_c (dimensionless, log)",
              "(f) conditioning (JacobiSVD of the solver's scaled KKT Jacobian)")
    legend_below(ax)


def panel_prediction(ax, res, pts, v):
    """(g) The medians of the IFT prediction error, on an axis of their own (with the tails they would
    share a few pixels)."""
    sm = [p[SMOOTHNESS] for p in pts]
    ax.plot(v, [s["ift_alpha_prediction_error_rel_change"]["p50"] for s in sm], "o-", color="C0", label="alpha*, median")
    ax.plot(v, [s["ift_normal_prediction_error_rel_change"]["p50"] for s in sm], "s--", color="C1", label="normal, median")
    over_grid(ax, res, "|IFT prediction - solve| / |change| (dimensionless, log)",
              "(g) first-order (IFT) prediction of the next pose's answer")
    legend_below(ax)


def panel_tails(ax, res, pts, v):
    """(h) The tails along the trajectory: the largest jumps per unit step, and the p99 of alpha*'s IFT
    prediction error (the turning points of the path)."""
    sm = [p[SMOOTHNESS] for p in pts]
    ax.plot(v, [s[AJUMP]["max"] for s in sm], "^-", color="C4", label="max |dalpha| / alpha per unit step")
    ax.plot(v, [s[NJUMP]["max"] for s in sm], "v-", color="C3", label="max |dn| per unit step")
    ax.plot(v, [s["ift_alpha_prediction_error_rel_change"]["p99"] for s in sm], "o--", color="C0", mfc="none",
            label="alpha*'s IFT prediction error / change, p99 (turning points)")
    over_grid(ax, res, "dimensionless, log (step = |(w, v/L)|)", "(h) the tails along the trajectory")
    legend_below(ax)


def plot(res, out_png):
    """One family's figure: eight panels over the grid's valid values, no two series drawn on each other,
    value labels placed so that they overlap neither each other nor the points and lines, at DPI."""
    par = res["parameter"]
    pts = valid_points(res)
    v = [p["value"] for p in pts]
    n_invalid = len(res["points"]) - len(pts)
    fig, ax = plt.subplots(4, 2, figsize=(14, 21), constrained_layout=True)
    fig.get_layout_engine().set(h_pad=0.12, hspace=0.06)
    for panel, a in zip((panel_error, panel_error_ratios, panel_time, panel_tradeoff, panel_iterations, panel_conditioning,
                         panel_prediction, panel_tails), ax.flat):
        labels = panel(a, res, pts, v)
        a.tick_params(labelsize=FONT - 1)
        if labels:
            series, labelled = labels, a
    n = res["sweep"]["poses"]
    inv = f", {n_invalid} invalid grid point(s) not shown (see the table)" if n_invalid else ""
    md = res["metadata"]
    fig.suptitle(f"{title_text(res['name'])}: {title_text(res['family'])} vs exact body, partner {title_text(res['partner'])}\n"
                 f"{n} poses per {title_text(par)} value, {len(pts)} values{inv}\n"
                 f"git {title_text(str(md.get('git_revision', '?'))[:10])}, {title_text(md.get('cpu_model', '?'))}, "
                 f"host {title_text(md.get('host', '?'))}", fontsize=FONT + 2)
    off = place_labels(fig, labelled, series, fontsize=FONT - 1)
    if off:
        labelled.set_title(labelled.get_title() + f", {off} label(s) left off where crowded", fontsize=FONT + 1)
    fig.savefig(out_png, dpi=DPI)
    plt.close(fig)


def machines_note(results):
    """A line naming each family's machine when the files come from more than one: their times do not compare."""
    cpu = {r["family"]: r.get("metadata", {}).get("cpu_model", "?") for r in results}
    if len(set(cpu.values())) <= 1:
        return ""
    by = {}
    for fam, c in cpu.items():
        by.setdefault(c, []).append(FAMILY_LABEL.get(fam, fam).split(" (")[0])
    return "\ntimes from different machines, not comparable across them: " + "; ".join(
        f"{', '.join(f)} on {title_text(c)}" for c, f in sorted(by.items()))


def plot_combined(results, out_png):
    """alpha* relative error p99 against median cold time per solve, one line per family."""
    fig, ax = plt.subplots(figsize=(13, 8), constrained_layout=True)
    series = []
    poses = sorted({r["sweep"]["poses"] for r in results})
    pins = sorted({pin_note(r) for r in results})
    for i, res in enumerate(results):
        pts = valid_points(res)
        tc = [p["timing"]["cold"]["time_ns"]["p50"] / 1e3 for p in pts]
        e99 = [p[ACC][AERR]["p99"] for p in pts]
        col = f"C{i}"
        ax.plot(tc, e99, "o-", color=col, label=f"{FAMILY_LABEL.get(res['family'], res['family'])}, "
                                                f"labels: {res['parameter']}")
        series.append((tc, e99, [f"{p['value']:g}" for p in pts], col))
    for t in sorted({threshold(r) for r in results}):
        ax.axhline(t, color="grey", lw=1, ls="-.", label=f"{percent(t)} threshold")
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_axis(ax, "x", f"median cold time per solve (us, log), {'; '.join(pins)}")
    log_axis(ax, "y", "alpha* relative error p99 (dimensionless, log)")
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    families = f"{len(results)} famil{'y' if len(results) == 1 else 'ies'}"
    ax.set_title(f"Smoothing studies: error against run time, {families}, "
                 f"{'/'.join(str(p) for p in poses)} poses per grid point\n"
                 f"(cold solves, partner sphere R = 0.75; one point per parameter value)" + machines_note(results),
                 fontsize=10)
    off = place_labels(fig, ax, series, fontsize=8)
    if off:
        ax.text(1.01, 0.0, f"{off} point label(s) left off\nwhere they would overlap;\nall values are in smoothing.md",
                transform=ax.transAxes, fontsize=8, va="bottom")
    fig.savefig(out_png, dpi=DPI)
    plt.close(fig)


def table(res):
    par = res["parameter"]
    lines = [f"### {md_text(res['name'])} ({md_text(res['family'])}, {res['sweep']['poses']} poses per point)", "",
             f"| {md_text(par)} | conv. cold / warm | alpha* err mean / p99 / max | radial gap (rel) | Hausdorff lower (rel) "
             "| cold us p50 / p99 | warm us p50 / p99 | iters cold / warm | rcond p50 / min | IFT alpha err/change p50 / p99 | max normal jump |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in res["points"]:
        if not p.get("valid"):
            lines.append(f"| {p['value']:g} | invalid: {md_text(p['invalid_reason'].split(': ')[-1])} |||||||||| ")
            continue
        e = p[ACC][AERR]
        t = p["timing"]
        c = p["conditioning"]["rcond_svd"]
        s = p[SMOOTHNESS]
        lines.append(
            f"| {p['value']:g} | {t['cold'][CONV]:.4f} / {t['warm'][CONV]:.4f} "
            f"| {e['mean']:.2e} / {e['p99']:.2e} / {e['max']:.2e} | {at(p, GAP):.2e} "
            f"| {at(p, HAUSDORFF):.2e} "
            f"| {t['cold']['time_ns']['p50'] / 1e3:.2f} / {t['cold']['time_ns']['p99'] / 1e3:.2f} "
            f"| {t['warm']['time_ns']['p50'] / 1e3:.2f} / {t['warm']['time_ns']['p99'] / 1e3:.2f} "
            f"| {t['cold'][ITERS]['mean']:.2f} / {t['warm'][ITERS]['mean']:.2f} "
            f"| {c['p50']:.1e} / {c['min']:.1e} | {s['ift_alpha_prediction_error_rel_change']['p50']:.2e} / "
            f"{s['ift_alpha_prediction_error_rel_change']['p99']:.2e} "
            f"| {s[NJUMP]['max']:.2e} |")
    r = recommend(res)
    lines.append("")
    if r is None:
        lines.append(f"Recommendation: no {par} in the grid meets alpha* p99 error < {percent(threshold(res))} with full "
                     "convergence.")
    else:
        lines.append(f"Recommendation (rule: smallest {par} with alpha* p99 relative error < {percent(threshold(res))} and every pose "
                     f"converged cold and warm): **{par} = {r['value']:g}** (p99 error "
                     f"{r[ACC][AERR]['p99']:.2e}, cold median "
                     f"{r['timing']['cold']['time_ns']['p50'] / 1e3:.2f} us, warm median "
                     f"{r['timing']['warm']['time_ns']['p50'] / 1e3:.2f} us).")
    lines.append(f"Failures saved for replay: {res['failure_count']} (in {md_code(res['failures_file'])}).")
    return "\n".join(lines) + "\n"


def load(path):
    """The results file, or None for a failure-record file; exit 2 on any other schema."""
    try:
        with open(path) as f:
            res = json.load(f)
    except (OSError, ValueError) as e:
        print(f"{path}: cannot read: {e}", file=sys.stderr)
        sys.exit(2)
    schema = res.get("schema") if isinstance(res, dict) else None
    if schema == "idcol-harness-failures":
        print(f"{path}: failure records (schema {schema}), skipped", file=sys.stderr)
        return None
    if schema != "idcol-smoothing-study":
        print(f"{path}: schema {schema!r}, not a smoothing-study results file (idcol-smoothing-study)", file=sys.stderr)
        sys.exit(2)
    return res


def family_rank(res):
    f = res.get("family")
    return FAMILY_ORDER.index(f) if f in FAMILY_ORDER else len(FAMILY_ORDER)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results", nargs="+")
    ap.add_argument("-o", "--outdir", default="results")
    ap.add_argument("--md", default=None)
    ap.add_argument("--combined", default=None, metavar="PNG",
                    help="also write one error-against-time figure across all the families given")
    a = ap.parse_args()
    loaded = []
    for path in a.results:
        res = load(path)
        if res is not None:
            loaded.append((path, res))
    if not loaded:
        print("no smoothing-study results file among the arguments", file=sys.stderr)
        sys.exit(2)
    loaded.sort(key=lambda pr: family_rank(pr[1]))  # stable: same family keeps argument order
    os.makedirs(a.outdir, exist_ok=True)
    md = []
    for path, res in loaded:
        # The figure's name comes from the results file's name, never from the
        # scene's `name` (free text from the config, which may hold "../").
        stem = os.path.basename(path)
        stem = stem[:-5] if stem.endswith(".json") else stem
        png = os.path.join(a.outdir, stem + ".png")
        plot(res, png)
        md.append(table(res))
        print(f"wrote {png}")
    if a.combined:
        plot_combined([r for _, r in loaded], a.combined)
        print(f"wrote {a.combined}")
    text = "\n".join(md)
    if a.md:
        with open(a.md, "w") as f:
            f.write(text)
        print(f"wrote {a.md}")
    else:
        print(text)


if __name__ == "__main__":
    main()
