#!/usr/bin/env python3
"""Plot time per drive step against the scene's size N (log-log) from Google Benchmark JSON files.

One curve per benchmark family: the benchmark name without its N argument, with its other arguments (lu, pred)
spelled out, e.g. "phiq KLU", "phiq UMFPACK", "dense Eigen LU, from previous", "Simbody, quadratic predictor".
With several files, each label ends with its file's name: "phiq KLU (klu_vs_umfpack)", or with the label given
as FILE=LABEL: "phiq KLU (50 steps per quarter turn)".

Time per step: the benchmark's per-step counter when it has one (us_per_step, ms_per_step, ns_per_step,
step_seconds or seconds_per_step), else its real_time in its time_unit (one iteration taken as one step) -- but
only in a file where no benchmark has such a counter: where some do, those without one are not per-step benchmarks
(phiq_bench's BM_NFourBarNewtonIterationVsKernel times one Newton iteration) and are left out. Skipped as well:
aggregates (mean, median, stddev of repetitions), benchmarks that failed (error_occurred), benchmarks without an N
argument (BM_Name/N:123/... or a first numeric argument, BM_Name/123/...), and what --exclude matches.

Writes an SVG (text kept as text, no timestamp: the same input gives the same file), and a PNG with --png.
Errors (unreadable file, invalid JSON, nothing to plot, unwritable output) are one line on stderr, exit status 1.

Example (the figure of bench/README.md):
  tools/plot/plot_bench.py bench/results/*.json -o bench/results/time_per_step.svg
Needs matplotlib (Debian: python3-matplotlib, installed by tools/install_deps.sh).
"""

import argparse
import json
import math
import os
import re
import sys

from plot_common import PlotError, pyplot, run, save

PROG = "plot_bench.py"

# Per-step counters a benchmark may report, and their unit in seconds.
STEP_COUNTERS = {
    "step_seconds": 1.0,
    "seconds_per_step": 1.0,
    "ms_per_step": 1e-3,
    "us_per_step": 1e-6,
    "ns_per_step": 1e-9,
}
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}

# Name parts that are run settings, not arguments.
SETTINGS = re.compile(r"^(manual_time|real_time|process_time|(iterations|repeats|min_time|min_warmup_time|threads)"
                      r":.*)$")

# Known families: label, and default values of arguments missing from older runs.
KNOWN = {
    # phiq_bench; its runs from before the `lu` argument existed are UMFPACK's
    "BM_NFourBarSweepStep": ("phiq", {"lu": "0"}),
    # phiq_bench_peers
    "BM_NFourBarStepPhiqKlu": ("phiq KLU", {}),
    "BM_NFourBarStepDenseEigenLu": ("dense Eigen LU", {}),
    "BM_NFourBarStepSimbody": ("Simbody", {}),
}
ARG_WORDS = {
    "lu": {"0": "UMFPACK", "1": "KLU"},
    "pred": {"0": "from previous", "1": "quadratic predictor"},
}


def parse_name(name):
    """'BM_X/N:10/lu:1/manual_time' -> ('BM_X', '10', [('lu', '1')]); N is None when absent."""
    parts = name.split("/")
    base, named, positional = parts[0], [], []
    for p in parts[1:]:
        if not p or SETTINGS.match(p):
            continue
        if ":" in p:
            k, v = p.split(":", 1)
            named.append((k, v))
        else:
            positional.append(p)
    n = None
    for k, v in named:
        if k in ("N", "n"):
            n = v
    named = [(k, v) for k, v in named if k not in ("N", "n")]
    if n is None and positional:
        n = positional.pop(0)
    named += [("arg%d" % (i + 1), v) for i, v in enumerate(positional)]
    return base, n, named


def family_label(base, args):
    label, defaults = KNOWN.get(base, (base[3:] if base.startswith("BM_") else base, {}))
    values = dict(defaults)
    values.update(dict(args))
    words = []
    for k, v in values.items():
        w = ARG_WORDS.get(k, {}).get(v)
        words.append(w if w is not None else "%s:%s" % (k, v))
    # the solver reads best right after the program's name: "phiq KLU"
    if "lu" in values and words:
        lu = words.pop(list(values).index("lu"))
        label = "%s %s" % (label, lu)
    return ", ".join([label] + words)


# The generated scene each family steps, from its name ("BM_NFourBarStepSimbody", "BM_GridStep", ...), for the
# axis label: the x axis says whose N it is.
SCENES = (("nfourbar", re.compile(r"nfourbar", re.I)), ("grid", re.compile(r"grid", re.I)),
          ("scissor", re.compile(r"scissor", re.I)), ("chain3d", re.compile(r"chain3d", re.I)))


def scene_of(base):
    for scene, rx in SCENES:
        if rx.search(base):
            return scene
    return None


def x_label(scenes):
    """The x axis's label for the scenes plotted (names, None for a family of no known scene)."""
    known = sorted(set(s for s in scenes if s))
    if known == ["nfourbar"] and None not in scenes:
        return "nfourbar N (N + 1 cranks, 2N + 3 natural coordinates)"
    if len(known) == 1 and None not in scenes:
        return "%s N (the size argument of phiq generate %s)" % (known[0], known[0])
    return "N, the size argument of each scene's generator (phiq generate %s N)" % "|".join(known or ["KIND"])


def step_counter(b):
    """Time per step (s) from a per-step counter, or None."""
    for key, scale in STEP_COUNTERS.items():
        if key in b:
            return float(b[key]) * scale
    return None


def real_time(b):
    unit = b.get("time_unit", "ns")
    if unit not in TIME_UNITS or "real_time" not in b:
        return None
    return float(b["real_time"]) * TIME_UNITS[unit]


def load(path, exclude=None):
    """Returns ({label: {N: [seconds, ...]}}, skipped, {label: scene or None}) for one file."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise PlotError("%s: cannot read: %s" % (path, e.strerror or e))
    try:
        data = json.loads(text)
    except ValueError as e:
        raise PlotError("%s: not valid JSON: %s" % (path, e))
    if not isinstance(data, dict) or not isinstance(data.get("benchmarks"), list):
        raise PlotError("%s: not a Google Benchmark JSON file (no 'benchmarks' list)" % path)
    entries = data["benchmarks"]
    for b in entries:
        if not isinstance(b, dict) or not isinstance(b.get("name"), str):
            raise PlotError("%s: a benchmark entry without a name" % path)
    counters_here = any(any(k in b for k in STEP_COUNTERS) for b in entries)
    curves, skipped, scenes = {}, {}, {}

    def skip(why):
        skipped[why] = skipped.get(why, 0) + 1

    for b in entries:
        if b.get("run_type") == "aggregate" or "aggregate_name" in b:
            skip("aggregate")
            continue
        if b.get("error_occurred"):
            skip("failed")
            continue
        if exclude and exclude.search(b["name"]):
            skip("excluded")
            continue
        base, n, args = parse_name(b.get("run_name") or b["name"])
        try:
            n = int(n) if n is not None else None
            t = step_counter(b)
            if t is None and not counters_here:
                t = real_time(b)
        except (TypeError, ValueError):
            raise PlotError("%s: %s: non-numeric N or time" % (path, b["name"]))
        if n is None or n <= 0:
            skip("no N")
            continue
        if t is None or not (t > 0 and math.isfinite(t)):
            skip("not per step")
            continue
        curves.setdefault(family_label(base, args), {}).setdefault(n, []).append(t)
        scenes[family_label(base, args)] = scene_of(base)
    return curves, skipped, scenes


def median(xs):
    xs = sorted(xs)
    m = len(xs) // 2
    return xs[m] if len(xs) % 2 else 0.5 * (xs[m - 1] + xs[m])


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json", nargs="+", metavar="JSON", help="Google Benchmark output (--benchmark_out_format=json), or FILE=LABEL to name its curves")
    ap.add_argument("-o", "--output", default="time_per_step.svg", metavar="OUT.svg",
                    help="SVG to write (default: time_per_step.svg)")
    ap.add_argument("--png", metavar="OUT.png", help="also write a PNG")
    ap.add_argument("--filter", metavar="REGEX", help="only curves whose label matches REGEX (re.search)")
    ap.add_argument("--exclude", metavar="REGEX", help="leave out benchmarks whose name matches REGEX")
    ap.add_argument("--title", help="title of the figure (default: the scenes plotted, and what is timed)")
    args = ap.parse_args(argv)

    try:
        exclude = re.compile(args.exclude) if args.exclude else None
    except re.error as e:
        raise PlotError("--exclude: invalid regular expression: %s" % e)
    # FILE=LABEL names the file's curves in the legend; a path that exists is taken whole.
    named = [(a, None) if os.path.exists(a) or "=" not in a else tuple(a.rsplit("=", 1)) for a in args.json]
    per_file = [(p, tag, load(p, exclude)) for p, tag in named]
    merged, scene_of_curve = {}, {}
    for p, tag, (curves, _, scenes) in per_file:
        stem = tag or os.path.splitext(os.path.basename(p))[0]
        for label, points in curves.items():
            name = label if len(args.json) == 1 else "%s (%s)" % (label, stem)
            scene_of_curve[name] = scenes[label]
            for n, ts in points.items():
                merged.setdefault(name, {}).setdefault(n, []).extend(ts)
    if args.filter:
        try:
            rx = re.compile(args.filter)
        except re.error as e:
            raise PlotError("--filter: invalid regular expression: %s" % e)
        merged = {k: v for k, v in merged.items() if rx.search(k)}
    if not merged:
        raise PlotError("nothing to plot: no benchmark with an N argument and a time%s in %s" %
                        (" matching --filter" if args.filter else "", ", ".join(args.json)))

    _, plt = pyplot()

    fig, ax = plt.subplots(figsize=(10, 5.5))
    markers = "os^vD<>phX*"
    colors = plt.get_cmap("tab20").colors
    for i, (label, points) in enumerate(sorted(merged.items())):
        ns = sorted(points)
        color = colors[(2 * i) % 20 + (i // 10) % 2]  # the 10 dark ones of tab20 first, then the light ones
        ax.plot(ns, [median(points[n]) for n in ns], marker=markers[i % len(markers)], label=label, color=color,
                linestyle="--" if "from previous" in label else "-")
    ax.set_xscale("log")
    ax.set_yscale("log")
    plotted = [scene_of_curve[label] for label in merged]
    ax.set_xlabel(x_label(plotted))
    ax.set_ylabel("time per drive step (s)")
    known = sorted(set(s for s in plotted if s))
    ax.set_title(args.title or "%s: time per drive step (position, velocity, acceleration)" %
                 (", ".join(known) if known else "benchmarks"), fontsize=10)
    ax.grid(True, which="both", linewidth=0.3, alpha=0.6)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    save(fig, args.output, args.png, svg_dpi=120, png_dpi=120)
    skipped = {}
    for _, _, (_, sk, _) in per_file:
        for why, k in sk.items():
            skipped[why] = skipped.get(why, 0) + k
    print("%s: %d curves -> %s%s%s" % (
        PROG, len(merged), args.output, " and " + args.png if args.png else "",
        "; skipped: " + ", ".join("%d %s" % (k, why) for why, k in sorted(skipped.items())) if skipped else ""),
        file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(run(main, PROG, sys.argv[1:]))
