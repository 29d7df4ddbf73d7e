#!/usr/bin/python3
"""Figures of the multibody example and of its scaling study, from their results files only.

usage: scripts/plot_multibody.py RESULTS.json [-o OUT.png] [--gif OUT.gif]
       scripts/plot_multibody.py --scaling SCALING.json [-o OUT.png]

RESULTS.json (core/examples/multibody.cpp, idcol_multibody -o): six snapshots
of the ten bodies like the paper's Fig. (contact physics, a): the start (red
arrows: the throwing velocities), then frames with contacts, each force as
an arrow at x* along the force on body 2 (solid) and the reaction on body 1
(dashed), its length growing with the square root of f_n, and the last
frame. Each body is drawn from the surface grid the
results file holds (its boundary along a latitude-longitude grid of rays,
body frame), placed at the frame's pose. --gif also writes an animation of
every frame (needs Pillow).

SCALING.json (core/bench/bench_multibody_scaling.cpp): the step's cost against
the number of bodies on log-log axes: (a) seconds per step of the broad
phase, the narrow phase, and the narrow phase with the wrench Jacobians, each
narrow phase also in the batch's SIMD lanes where the file has it; (b)
microseconds per body of the whole step, and of the three broad-phase
methods alone, beside log N.

Nothing is rerun; the numbers come from the JSON files. Exit 2 on a file
that is not of the expected kind.
"""
import argparse
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(path, kind_key, kind):
    with open(path) as f:
        d = json.load(f)
    if d.get(kind_key) != kind:
        print(f"plot_multibody: {path} is not a {kind} results file ({kind_key} = {d.get(kind_key)!r})", file=sys.stderr)
        sys.exit(2)
    return d


def pick_frames(frames, n=6):
    """The start, the first frame with a contact, the frame with the most,
    two frames with contacts between them, and the last."""
    with_contacts = [k for k, f in enumerate(frames) if f["contacts"]]
    chosen = {0, len(frames) - 1}
    if with_contacts:
        most = max(with_contacts, key=lambda k: (len(frames[k]["contacts"]), -k))
        chosen |= {with_contacts[0], most}
        rest = [k for k in with_contacts if k not in chosen]
        for q in np.linspace(0, len(rest) - 1, min(len(rest), n - len(chosen))).round().astype(int) if rest else []:
            chosen.add(rest[q])
    return sorted(chosen)[:n]


def body_surfaces(scene):
    out = []
    for b in scene["bodies"]:
        g = b["surface"]
        out.append(np.array(g["points"]).reshape(g["nlat"], g["nlon"], 3))
    return out


def draw_frame(ax, scene, surfaces, frame, colors, lim, arrow_scale, first):
    for i, pts in enumerate(surfaces):
        R = np.array(frame["R"][i]).reshape(3, 3)
        p = np.array(frame["p"][i])
        w = pts @ R.T + p
        ax.plot_surface(w[..., 0], w[..., 1], w[..., 2], color=colors[i], alpha=0.55, linewidth=0, shade=True)
    if first:  # the throwing velocities
        for i in range(len(surfaces)):
            p = np.array(frame["p"][i])
            v = -p / max(np.linalg.norm(p), 1e-12) * 1.5
            ax.quiver(*p, *v, color="red", linewidth=1.5, arrow_length_ratio=0.25)
    for c in frame["contacts"]:
        x, n = np.array(c["x"]), np.array(c["normal"])
        # The force on body 2 is +f_n n (body 1 is pushed along -n); the
        # length grows with the square root of f_n, so that small forces show.
        f = n * (0.4 + 1.4 * math.sqrt(c["f_n"] * arrow_scale))
        ax.quiver(*x, *f, color="black", linewidth=1.4, arrow_length_ratio=0.25)
        ax.quiver(*x, *(-f), color="black", linewidth=1.0, linestyle="dashed", arrow_length_ratio=0.25)
    ax.set_xlim(-lim, lim), ax.set_ylim(-lim, lim), ax.set_zlim(-lim, lim)
    ax.set_box_aspect((1, 1, 1))
    ax.set_title(f"t = {frame['t']:.2f} s, {len(frame['contacts'])} contacts", fontsize=9)
    ax.tick_params(labelsize=6)


def snapshots(d, out, gif):
    scene, frames = d["scene"], d["frames"]
    surfaces = body_surfaces(scene)
    colors = plt.cm.tab10(np.arange(len(surfaces)) % 10)
    lim = max(max(np.abs(np.array(f["p"])).max() for f in frames), 1.0) + 1.0
    fmax = max([c["f_n"] for f in frames for c in f["contacts"]] + [1e-12])
    arrow_scale = 1.0 / fmax  # the largest force drawn 1.8 units long
    picks = pick_frames(frames)
    fig = plt.figure(figsize=(15, 9.5))
    for k, idx in enumerate(picks):
        ax = fig.add_subplot(2, 3, k + 1, projection="3d")
        draw_frame(ax, scene, surfaces, frames[idx], colors, lim if k in (0, len(picks) - 1) else lim * 0.45,
                   arrow_scale, k == 0)
    names = ", ".join(b["name"] for b in scene["bodies"])
    run = d["runs"]["analytic"]
    fig.suptitle(f"Ten bodies ({names}) thrown at the origin at {scene['speed']} units/s; Hertz k = "
                 f"{scene['contact']['stiffness']:g}, p = {scene['contact']['exponent']:g}; {run['steps']} steps, "
                 f"{run['wall_seconds']['median']:.3f} s (git {d['git_revision']})", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print(f"wrote {out}")
    if gif:
        from matplotlib import animation

        fig = plt.figure(figsize=(6, 6))
        ax = fig.add_subplot(projection="3d")

        def update(k):
            ax.clear()
            draw_frame(ax, scene, surfaces, frames[k], colors, lim * 0.6, arrow_scale, k == 0)

        anim = animation.FuncAnimation(fig, update, frames=len(frames))
        anim.save(gif, writer=animation.PillowWriter(fps=10))
        print(f"wrote {gif}")


def scaling(d, out):
    rows = d["sizes"]
    n = np.array([r["bodies"] for r in rows], float)
    broad = np.array([r["broad_seconds"] for r in rows])
    narrow = np.array([r["narrow_seconds"] for r in rows])
    narrow_j = np.array([r["narrow_seconds_with_jacobians"] for r in rows])
    broad_j = np.array([r["broad_seconds_with_jacobians"] for r in rows])
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.8))
    a.loglog(n, broad, "o-", label="broad phase")
    a.loglog(n, narrow, "s-", label="narrow phase (wrenches)")
    a.loglog(n, narrow_j, "^-", label="narrow phase (wrenches + Jacobians)")
    if all("narrow_seconds_lanes" in r for r in rows):  # the same in the batch's SIMD lanes
        lanes = d.get("lanes", "SIMD")
        a.loglog(n, [r["narrow_seconds_lanes"] for r in rows], "s:", color="C1", alpha=0.6,
                 label=f"narrow phase (wrenches), {lanes} lanes")
        a.loglog(n, [r["narrow_seconds_with_jacobians_lanes"] for r in rows], "^:", color="C2", alpha=0.6,
                 label=f"narrow phase (wrenches + Jacobians), {lanes} lanes")
    a.loglog(n, n * (broad_j + narrow_j)[-1] / n[-1], "k:", label="slope 1 (linear)")
    a.set_xlabel("bodies N"), a.set_ylabel("seconds per step"), a.legend(fontsize=8), a.grid(True, which="both", alpha=0.3)
    a.set_title("(a) one step's contact detection")
    per_body = 1e6 * (broad_j + narrow_j) / n
    b.loglog(n, per_body, "o-", label="whole step, with Jacobians")
    for key, mark in (("tree", "s--"), ("sweep_and_prune", "^--"), ("all_pairs", "v--")):
        vals = [(r["bodies"], r["broad_phase_alone"][key]) for r in rows if r["broad_phase_alone"][key] is not None]
        if vals:
            x, y = np.array(vals).T
            b.loglog(x, 1e6 * y / x, mark, label=f"broad phase alone: {key.replace('_', ' ')}")
    ref = per_body[1] if len(per_body) > 1 else per_body[0]
    n0 = n[1] if len(n) > 1 else n[0]
    b.loglog(n, ref * np.log(n) / math.log(n0), "k:", label="proportional to log N")
    b.set_xlabel("bodies N"), b.set_ylabel("microseconds per body"), b.legend(fontsize=8)
    b.grid(True, which="both", alpha=0.3)
    b.set_title("(b) cost per body")
    contacts = ", ".join(f"{r['contacts_per_step'] / r['bodies']:.2f}" for r in rows)
    fig.suptitle(f"Box scene, one body per unit cell; contacts per body {contacts}; {d['machine']['cpu']}, git {d['git_revision']}",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results")
    ap.add_argument("-o", "--out")
    ap.add_argument("--scaling", action="store_true", help="RESULTS is a multibody_scaling file")
    ap.add_argument("--gif", help="also an animation of every frame (snapshots only)")
    a = ap.parse_args()
    if a.scaling:
        d = load(a.results, "benchmark", "multibody_scaling")
        scaling(d, a.out or os.path.splitext(a.results)[0] + ".png")
    else:
        d = load(a.results, "example", "multibody")
        snapshots(d, a.out or os.path.splitext(a.results)[0] + ".png", a.gif)


if __name__ == "__main__":
    main()
