#!/usr/bin/python3
"""Figures and a summary table for the smoothing study, from its results files only.

usage: scripts/plot_smoothing.py results/smoothing_*.json [-o results/] [--md results/smoothing.md]

For each results file (one family) writes <name>.png with four panels:
  (a) alpha* relative error (p99, max) and radial gap (Hausdorff upper-bound
      estimate) against median time per solve, one point per parameter value,
      cold (circles) and warm (triangles) at the same error;
  (b) iterations (cold and warm mean, cold p99) against the parameter;
  (c) conditioning sigma_min/sigma_max of the KKT Jacobian (p50, p01, min)
      against the parameter;
  (d) smoothness: IFT first-order prediction error relative to the change
      (alpha* and normal, p99) and the largest normal jump per unit step.
The recommendation rule: the smallest parameter value whose alpha* error
stays under 1 % at p99 and whose cold and warm passes converged on every pose.
Nothing is rerun; the numbers come from the JSON files.
"""
import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

THRESH = 0.01


def valid_points(res):
    return [p for p in res["points"] if p.get("valid")]


def cold_pass_converged_fraction(p):
    # From the status counts: results made at git 9ab679f stored a wrong
    # cold_accuracy_pass.converged_fraction (0, a status-key typo since fixed).
    c = p["cold_accuracy_pass"]
    return c["statuses"].get("converged", 0) / c["poses"]


def recommend(res):
    for p in valid_points(res):
        e = p["cold_accuracy_pass"]["alpha_rel_error"].get("p99")
        t = p["timing"]
        if e is not None and e < THRESH and t["cold"]["converged_fraction"] == 1.0 and t["warm"]["converged_fraction"] == 1.0 \
                and cold_pass_converged_fraction(p) == 1.0:
            return p
    return None


def plot(res, out_png):
    par = res["parameter"]
    pts = valid_points(res)
    v = [p["value"] for p in pts]
    fig, ax = plt.subplots(2, 2, figsize=(10, 7.5))
    a = ax[0, 0]
    e99 = [p["cold_accuracy_pass"]["alpha_rel_error"]["p99"] for p in pts]
    emax = [p["cold_accuracy_pass"]["alpha_rel_error"]["max"] for p in pts]
    gap = [p["geometry"]["radial_gap_max_rel"] for p in pts]
    tc = [p["timing"]["cold"]["time_ns"]["p50"] / 1e3 for p in pts]
    tw = [p["timing"]["warm"]["time_ns"]["p50"] / 1e3 for p in pts]
    a.plot(tc, e99, "o-", color="C0", label="alpha* rel. error p99, cold")
    a.plot(tw, e99, "^--", color="C0", label="alpha* rel. error p99, warm", alpha=0.7)
    a.plot(tc, emax, "o:", color="C1", label="alpha* rel. error max, cold", ms=4)
    a.plot(tc, gap, "s-", color="C2", label="radial gap / outer radius, cold", ms=4)
    for x, y, val in zip(tc, e99, v):
        a.annotate(f"{val:g}", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    a.axhline(THRESH, color="grey", lw=0.8, ls=":")
    a.set_xlabel("median time per solve (us), one thread pinned, shared VM")
    a.set_ylabel("relative error")
    a.set_yscale("log")
    a.set_title(f"(a) error vs time (labels: {par})", fontsize=9)
    a.legend(fontsize=7)

    b = ax[0, 1]
    b.plot(v, [p["timing"]["cold"]["iterations"]["mean"] for p in pts], "o-", label="cold mean")
    b.plot(v, [p["timing"]["cold"]["iterations"]["p99"] for p in pts], "o:", label="cold p99")
    b.plot(v, [p["timing"]["warm"]["iterations"]["mean"] for p in pts], "^-", label="warm mean")
    b.set_xscale("log")
    b.set_xlabel(par)
    b.set_ylabel("Newton iterations per solve")
    b.set_title("(b) iterations", fontsize=9)
    b.legend(fontsize=7)

    c = ax[1, 0]
    for key, st, lab in (("p50", "o-", "median"), ("p01", "s--", "1st percentile"), ("min", "v:", "min")):
        c.plot(v, [p["conditioning"]["rcond_svd"][key] for p in pts], st, label=lab)
    c.set_xscale("log")
    c.set_yscale("log")
    c.set_xlabel(par)
    c.set_ylabel("sigma_min / sigma_max of J_c at the solution")
    c.set_title("(c) conditioning (JacobiSVD of the solver's scaled KKT Jacobian)", fontsize=9)
    c.legend(fontsize=7)

    d = ax[1, 1]
    sm = [p["smoothness"] for p in pts]
    d.plot(v, [s["ift_alpha_prediction_error_rel_change"]["p50"] for s in sm], "o-", label="IFT alpha* pred. err / change, median")
    d.plot(v, [s["ift_normal_prediction_error_rel_change"]["p50"] for s in sm], "s-", label="IFT normal pred. err / change, median")
    d.plot(v, [s["ift_alpha_prediction_error_rel_change"]["p99"] for s in sm], "o--", ms=3,
           label="IFT alpha* pred. err / change, p99 (turning points)")
    d.plot(v, [s["normal_jump_per_step"]["max"] for s in sm], "v:", label="max |dn| per unit step")
    d.plot(v, [s["alpha_jump_rel_per_step"]["max"] for s in sm], "^:", label="max |dalpha|/alpha per unit step")
    d.set_xscale("log")
    d.set_yscale("log")
    d.set_xlabel(par)
    d.set_title("(d) smoothness along the trajectory", fontsize=9)
    d.legend(fontsize=7)

    n = res["sweep"]["poses"]
    fig.suptitle(f"{res['name']}: {res['family']} vs exact body, partner {res['partner']}, {n} poses per point\n"
                 f"git {res['metadata'].get('git_revision', '?')[:10]}, {res['metadata'].get('cpu_model', '?')}",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(out_png, dpi=80)
    plt.close(fig)


def table(res):
    par = res["parameter"]
    lines = [f"### {res['name']} ({res['family']}, {res['sweep']['poses']} poses per point)", "",
             f"| {par} | conv. cold / warm | alpha* err mean / p99 / max | radial gap (rel) | Hausdorff lower (rel) "
             "| cold us p50 / p99 | warm us p50 / p99 | iters cold / warm | rcond p50 / min | IFT alpha err/change p50 / p99 | max normal jump |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in res["points"]:
        if not p.get("valid"):
            lines.append(f"| {p['value']:g} | invalid: {p['invalid_reason'].split(': ')[-1]} |||||||||| ")
            continue
        e = p["cold_accuracy_pass"]["alpha_rel_error"]
        t = p["timing"]
        c = p["conditioning"]["rcond_svd"]
        s = p["smoothness"]
        lines.append(
            f"| {p['value']:g} | {t['cold']['converged_fraction']:.4f} / {t['warm']['converged_fraction']:.4f} "
            f"| {e['mean']:.2e} / {e['p99']:.2e} / {e['max']:.2e} | {p['geometry']['radial_gap_max_rel']:.2e} "
            f"| {p['geometry']['hausdorff_lower_rel']:.2e} "
            f"| {t['cold']['time_ns']['p50'] / 1e3:.2f} / {t['cold']['time_ns']['p99'] / 1e3:.2f} "
            f"| {t['warm']['time_ns']['p50'] / 1e3:.2f} / {t['warm']['time_ns']['p99'] / 1e3:.2f} "
            f"| {t['cold']['iterations']['mean']:.2f} / {t['warm']['iterations']['mean']:.2f} "
            f"| {c['p50']:.1e} / {c['min']:.1e} | {s['ift_alpha_prediction_error_rel_change']['p50']:.2e} / "
            f"{s['ift_alpha_prediction_error_rel_change']['p99']:.2e} "
            f"| {s['normal_jump_per_step']['max']:.2e} |")
    r = recommend(res)
    lines.append("")
    if r is None:
        lines.append(f"Recommendation: no {par} in the grid meets alpha* p99 error < 1 % with full convergence.")
    else:
        lines.append(f"Recommendation (rule: smallest {par} with alpha* p99 relative error < 1 % and every pose "
                     f"converged cold and warm): **{par} = {r['value']:g}** (p99 error "
                     f"{r['cold_accuracy_pass']['alpha_rel_error']['p99']:.2e}, cold median "
                     f"{r['timing']['cold']['time_ns']['p50'] / 1e3:.2f} us, warm median "
                     f"{r['timing']['warm']['time_ns']['p50'] / 1e3:.2f} us).")
    lines.append(f"Failures saved for replay: {res['failure_count']} (in `{res['failures_file']}`).")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("results", nargs="+")
    ap.add_argument("-o", "--outdir", default="results")
    ap.add_argument("--md", default=None)
    a = ap.parse_args()
    md = []
    for path in a.results:
        with open(path) as f:
            res = json.load(f)
        if res.get("schema") != "idcol-smoothing-study":
            sys.exit(f"{path}: not a smoothing-study results file")
        png = os.path.join(a.outdir, res["name"] + ".png")
        plot(res, png)
        md.append(table(res))
        print(f"wrote {png}")
    text = "\n".join(md)
    if a.md:
        with open(a.md, "w") as f:
            f.write(text)
        print(f"wrote {a.md}")
    else:
        print(text)


if __name__ == "__main__":
    main()
