#!/usr/bin/env python3
"""Plot error against time per step from `phiq sweep-accuracy` CSV files, with the Pareto front highlighted.

One row of panels per scene (the CSV's `scene` column), one panel per error: positions (err_q), velocities (err_v),
accelerations (err_a), each against us_per_step, both axes logarithmic. One marker style per knob:
  colour      Newton tolerance (dark = tight)
  shape       predictor (previous o, secant s, linear ^, quadratic D, auto *)
  fill        Newton: filled = modified, hollow = full
  size        step count (small = fewest steps of that scene)
  opacity     sparse LU: KLU opaque, UMFPACK faint (dense fainter still)
The Pareto front (no other setting is both faster per step and at most as inaccurate) is taken among the settings
with the scene's own step count, the default's: the step count is the time resolution of the output, which the
scene asks for, and a step of a finer sweep is cheaper but there are more of them. That front is the black staircase
with ringed points; the fronts of the other step counts are dotted grey. The scene's default setting (`default` =
1) is marked with a red ring.

On standard error, per scene and error: whether the default is on its step count's front, and if not, the fastest
setting that dominates it; and the same over all step counts. With --markdown FILE, the positions' front of every
scene (at its default step count) as a Markdown table (the table of bench/README.md), the default's row marked,
and a second table: every predictor, Newton mode and LU at the default's tolerance and step count.

Rows whose status is not "ok" (failed sweeps) are counted and left out. Errors of exactly 0 are drawn at 1e-17.
Writes an SVG (text kept as text, no timestamp: the same input gives the same file), and a PNG with --png.
Errors (unreadable file, not a sweep-accuracy CSV, nothing to plot, unwritable output) are one line on stderr,
exit status 1.

Example (the figure of bench/README.md):
  tools/plot/plot_accuracy.py bench/results/accuracy_*.csv -o bench/results/accuracy_pareto.svg
Needs matplotlib (Debian: python3-matplotlib, installed by tools/install_deps.sh).
"""

import argparse
import csv
import math
import sys

from plot_common import PlotError, pyplot, run, save

PROG = "plot_accuracy.py"
COLUMNS = ["scene", "reference", "tolerance", "steps", "predictor", "newton", "linear_solver", "err_q", "err_v",
           "err_a", "iterations_per_step", "factorizations_per_step", "us_per_step", "status", "default"]
ERRORS = [("err_q", "positions"), ("err_v", "velocities"), ("err_a", "accelerations")]
SHAPES = {"previous": "o", "secant": "s", "parabolic": "p", "linear": "^", "quadratic": "D", "cubic": "v",
          "auto": "*"}
ALPHA = {"klu": 0.95, "umfpack": 0.35, "dense": 0.2}
FLOOR = 1e-17


def load(path):
    """Rows of one sweep-accuracy CSV as dicts with numbers converted; (rows, failed count)."""
    try:
        with open(path, encoding="utf-8", newline="") as f:
            reader = csv.reader(f)
            header = next(reader, None)
            if header != COLUMNS:
                raise PlotError("%s: not a phiq sweep-accuracy CSV (expected the header %s)" % (path, ",".join(COLUMNS)))
            rows, failed = [], 0
            for lineno, cells in enumerate(reader, start=2):
                if len(cells) != len(COLUMNS):
                    raise PlotError("%s:%d: %d fields, expected %d" % (path, lineno, len(cells), len(COLUMNS)))
                r = dict(zip(COLUMNS, cells))
                if r["status"] != "ok":
                    failed += 1
                    continue
                try:
                    for k in ("tolerance", "us_per_step", "iterations_per_step", "factorizations_per_step"):
                        r[k] = float(r[k])
                    r["steps"] = int(r["steps"])
                    for k, _ in ERRORS:
                        r[k] = float(r[k]) if r[k] != "" else None
                except ValueError:
                    raise PlotError("%s:%d: a number column is not a number" % (path, lineno))
                r["default"] = r["default"] == "1"
                rows.append(r)
            return rows, failed
    except OSError as e:
        raise PlotError("%s: cannot read: %s" % (path, e.strerror or e))
    except csv.Error as e:
        raise PlotError("%s: not valid CSV: %s" % (path, e))


def pareto(points):
    """Indices of the points (time, error) that no other point dominates (<= in both, < in one), by time."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], math.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def label(r):
    return "tol %s, %d steps, %s, %s Newton, %s" % (fmt(r["tolerance"]), r["steps"], r["predictor"], r["newton"],
                                                     r["linear_solver"].upper())


def fmt(x):
    return "%.0e" % x if x != 0 else "0"


def main_steps(rows):
    """The step count whose front is drawn in black: the default's, else the most common one (then the smallest)."""
    d = [r["steps"] for r in rows if r["default"]]
    if d:
        return d[0]
    counts = {}
    for r in rows:
        counts[r["steps"]] = counts.get(r["steps"], 0) + 1
    return min(counts, key=lambda s: (-counts[s], s))


def check_default(scene, rows, key, same_steps):
    """One line: is the default on this panel's front (among its step count's settings, or among all); if not, the
    fastest setting that dominates it."""
    d = [r for r in rows if r["default"] and r[key] is not None]
    if not d:
        return None
    d = d[0]
    where = "at %d steps" % d["steps"] if same_steps else "over all step counts"
    if same_steps:
        rows = [r for r in rows if r["steps"] == d["steps"]]
    e = max(d[key], FLOOR)
    dominating = [r for r in rows if r is not d and r[key] is not None and r["us_per_step"] <= d["us_per_step"] and
                  max(r[key], FLOOR) <= e and (r["us_per_step"] < d["us_per_step"] or max(r[key], FLOOR) < e)]
    if not dominating:
        return "%s: %s: %s, the default (%s) is on the front" % (scene, key, where, label(d))
    best = min(dominating, key=lambda r: (r["us_per_step"], r[key]))
    return "%s: %s: %s, the default (%s; %.3g us, %.2g) is dominated by %s (%.3g us, %.2g): %.0f %% faster" % (
        scene, key, where, label(d), d["us_per_step"], d[key], label(best), best["us_per_step"], best[key],
        100.0 * (d["us_per_step"] / best["us_per_step"] - 1.0))


def markdown(scenes):
    """The positions' Pareto front of each scene, plus its default, as a Markdown table."""
    out = ["| scene | tolerance | steps | predictor | Newton | LU | err_q | err_v | err_a | iterations / step | "
           "factorisations / step | µs / step | |",
           "| --- | ---: | ---: | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
    for scene, rows in scenes:
        steps = main_steps(rows)
        rows = [r for r in rows if r["steps"] == steps]
        pts = [(r["us_per_step"], max(r["err_q"], FLOOR)) for r in rows]
        front = set(pareto(pts))
        keep = sorted([i for i in range(len(rows)) if i in front or rows[i]["default"]],
                      key=lambda i: rows[i]["us_per_step"])
        for i in keep:
            r = rows[i]
            mark = ", ".join(w for w, on in (("front", i in front), ("**default**", r["default"])) if on)
            errs = ["%.1e" % r[k] if r[k] is not None else "—" for k, _ in ERRORS]
            out.append("| %s | %s | %d | %s | %s | %s | %s | %s | %s | %.2f | %.2f | %.3g | %s |" % (
                scene, fmt(r["tolerance"]), r["steps"], r["predictor"], r["newton"], r["linear_solver"].upper(),
                errs[0], errs[1], errs[2], r["iterations_per_step"], r["factorizations_per_step"], r["us_per_step"],
                mark))
    out += ["", "At the default's tolerance and step count, every predictor, Newton mode and LU:", "",
            "| scene | predictor | Newton | LU | err_q | err_v | err_a | iterations / step | factorisations / step | "
            "µs / step | ÷ default |",
            "| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for scene, rows in scenes:
        d = [r for r in rows if r["default"]]
        if not d:
            continue
        d = d[0]
        same = [r for r in rows if r["tolerance"] == d["tolerance"] and r["steps"] == d["steps"]]
        for r in sorted(same, key=lambda r: (r["linear_solver"] != d["linear_solver"], r["us_per_step"])):
            errs = ["%.1e" % r[k] if r[k] is not None else "—" for k, _ in ERRORS]
            out.append("| %s | %s | %s | %s | %s | %s | %s | %.2f | %.2f | %.3g | %s |" % (
                scene, r["predictor"] + (" (**default**)" if r["default"] else ""), r["newton"],
                r["linear_solver"].upper(), errs[0], errs[1], errs[2], r["iterations_per_step"],
                r["factorizations_per_step"], r["us_per_step"], "%.2f" % (r["us_per_step"] / d["us_per_step"])))
    return "\n".join(out) + "\n"


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv", nargs="+", metavar="CSV", help="output of phiq sweep-accuracy")
    ap.add_argument("-o", "--output", default="accuracy_pareto.svg", metavar="OUT.svg",
                    help="SVG to write (default: accuracy_pareto.svg)")
    ap.add_argument("--png", metavar="OUT.png", help="also write a PNG")
    ap.add_argument("--markdown", metavar="OUT.md", help="also write the positions' Pareto fronts as a Markdown table")
    ap.add_argument("--title", default="phiq: error against time per drive step, per solver setting")
    args = ap.parse_args(argv)

    scenes, failed = {}, 0
    for p in args.csv:
        rows, f = load(p)
        failed += f
        for r in rows:
            scenes.setdefault(r["scene"], []).append(r)
    if not scenes:
        raise PlotError("nothing to plot: no successful row in %s" % ", ".join(args.csv))
    scenes = sorted(scenes.items())

    _, plt = pyplot()
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter

    tols = sorted({r["tolerance"] for _, rows in scenes for r in rows})
    cmap = plt.get_cmap("viridis")
    lo, hi = math.log10(min(tols)), math.log10(max(tols))

    def colour(t):
        return cmap(0.0 if hi == lo else 0.9 * (math.log10(t) - lo) / (hi - lo))

    fig, axes = plt.subplots(len(scenes), 3, figsize=(15, 4.2 * len(scenes) + 1.2), squeeze=False)
    messages = []
    for row_i, (scene, rows) in enumerate(scenes):
        steps = sorted({r["steps"] for r in rows})
        for col, (key, what) in enumerate(ERRORS):
            ax = axes[row_i][col]
            pts = [r for r in rows if r[key] is not None]
            if not pts:
                ax.text(0.5, 0.5, "%s not computed by this scene" % what, ha="center", va="center",
                        transform=ax.transAxes, fontsize=9)
                ax.set_axis_off()
                continue
            # one scatter per marker style (predictor, Newton, LU, steps), colours per point; the cloud is
            # rasterised inside the SVG (a thousand settings as vector markers make a megabyte), the fronts, the
            # default and all text stay vectors
            groups = {}
            for r in pts:
                groups.setdefault((r["predictor"], r["newton"], r["linear_solver"], r["steps"]), []).append(r)
            for (pred, newton, lu, st), g in sorted(groups.items()):
                cs = [colour(r["tolerance"]) for r in g]
                ax.scatter([r["us_per_step"] for r in g], [max(r[key], FLOOR) for r in g],
                           s=18 + 30 * steps.index(st), marker=SHAPES.get(pred, "x"),
                           facecolors=cs if newton == "modified" else "none", edgecolors=cs, linewidths=1.0,
                           alpha=ALPHA.get(lu, 0.5), zorder=2, rasterized=True)
            black = main_steps(pts)
            for st in steps:
                group = [r for r in pts if r["steps"] == st]
                if not group:
                    continue
                xy = [(r["us_per_step"], max(r[key], FLOOR)) for r in group]
                front = pareto(xy)
                fx = [xy[i][0] for i in front]
                fy = [xy[i][1] for i in front]
                if st == black:
                    ax.step(fx, fy, where="post", color="black", linewidth=1.3, zorder=3)
                    ax.scatter(fx, fy, s=90, facecolors="none", edgecolors="black", linewidths=1.2, zorder=4)
                else:
                    ax.step(fx, fy, where="post", color="0.55", linewidth=0.9, linestyle=":", zorder=1)
            for r in pts:
                if r["default"]:
                    ax.scatter([r["us_per_step"]], [max(r[key], FLOOR)], s=260, facecolors="none",
                               edgecolors="red", linewidths=2.0, zorder=5)
            for same in (True, False):
                msg = check_default(scene, pts, key, same)
                if msg:
                    messages.append(msg)
            ax.set_xscale("log")
            ax.set_yscale("log")
            # µs as plain numbers (0.5, 2, 300), labelled at 1, 2 and 5 of each decade
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % v))
            ax.xaxis.set_minor_formatter(FuncFormatter(
                lambda v, _: "%g" % v if round(v / 10 ** math.floor(math.log10(v) + 1e-9)) in (2, 5) else ""))
            ax.grid(True, which="both", linewidth=0.3, alpha=0.6)
            ax.set_title("%s: %s" % (scene, what), fontsize=9)
            ax.set_xlabel("time per drive step (µs, best of the timing rounds)", fontsize=8)
            ax.set_ylabel("worst error (%s)" % {"err_q": "scaled by the length scale",
                                               "err_v": "1/s, scaled", "err_a": "1/s², scaled"}[key], fontsize=8)
            ax.tick_params(labelsize=7)

    # One legend per knob, built from proxies.
    grey = "0.3"
    handles = [Line2D([], [], linestyle="", marker="o", markerfacecolor=colour(t), markeredgecolor=colour(t),
                      label="tol %s" % fmt(t)) for t in tols]
    handles += [Line2D([], [], linestyle="", marker=m, color=grey, label=p) for p, m in SHAPES.items()
                if any(r["predictor"] == p for _, rows in scenes for r in rows)]
    handles += [Line2D([], [], linestyle="", marker="o", color=grey, label="modified Newton"),
                Line2D([], [], linestyle="", marker="o", markerfacecolor="none", markeredgecolor=grey,
                       label="full Newton")]
    handles += [Line2D([], [], linestyle="", marker="o", color=grey, alpha=a, label=lu.upper())
                for lu, a in ALPHA.items() if any(r["linear_solver"] == lu for _, rows in scenes for r in rows)]
    handles += [Line2D([], [], linestyle="", marker="o", markersize=ms, color=grey, label=w)
                for ms, w in ((4, "fewer steps"), (9, "more steps"))]
    handles += [Line2D([], [], color="black", marker="o", markerfacecolor="none",
                       label="Pareto front (default's steps)"),
                Line2D([], [], color="0.55", linestyle=":", label="front, other steps"),
                Line2D([], [], linestyle="", marker="o", markersize=12, markerfacecolor="none",
                       markeredgecolor="red", label="scene default")]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 11), fontsize=7, frameon=False)
    fig.suptitle(args.title, fontsize=10)
    fig.tight_layout(rect=(0, 0.06 if len(scenes) > 1 else 0.1, 1, 0.97))
    save(fig, args.output, args.png, svg_dpi=72, png_dpi=110)  # svg: the resolution of the rasterised cloud
    if args.markdown:
        try:
            with open(args.markdown, "w", encoding="utf-8") as f:
                f.write(markdown(scenes))
        except OSError as e:
            raise PlotError("%s: cannot write: %s" % (args.markdown, e.strerror or e))
    for m in messages:
        print("%s: %s" % (PROG, m), file=sys.stderr)
    print("%s: %d scenes, %d settings -> %s%s%s" % (
        PROG, len(scenes), sum(len(rows) for _, rows in scenes), args.output,
        " and " + args.png if args.png else "", "; %d failed settings left out" % failed if failed else ""),
        file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(run(main, PROG, sys.argv[1:]))
