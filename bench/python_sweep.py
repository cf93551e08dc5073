#!/usr/bin/python3
"""What calling phiq from Python costs: phiq.run_sweep on nfourbar N (q, q̇, q̈ of every coordinate at every row)
timed as a whole from Python, against the time the same sweep spends inside the C++ run_sweep (its summary's
solve_seconds, measured in C++ around run_sweep, the row copies into the result's table included — what a C++
program that keeps its rows pays too). The difference is the Python side: the call, the assembly check
(prepare_scene), the column names, the table's allocation and the numpy views. Target (issue 24): at most 5 %.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_sweep.py build/tools/phiq [N ...]

Prints one line per N: steps, the median of 5 runs of each time, their ratio and its spread (min–max of the
per-run ratios)."""
import os
import statistics
import subprocess
import sys
import tempfile
import time

import phiq


def measure(cli, n, steps, runs=5):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "scene.yaml")
        subprocess.run([cli, "generate", "nfourbar", str(n), "--steps", str(steps), "--outputs", "q,v,a", "-o", path],
                       check=True)
        scene = phiq.load_scene(path)
    totals, inside, ratios = [], [], []
    for _ in range(runs):
        start = time.perf_counter()
        result = phiq.run_sweep(scene, threads=1)
        total = time.perf_counter() - start
        assert result.ok and result.table.shape == (steps + 1, 1 + 3 * (2 * n + 3))
        totals.append(total)
        inside.append(result.summary["solve_seconds"])
        ratios.append(total / result.summary["solve_seconds"])
        del result
    return statistics.median(totals), statistics.median(inside), statistics.median(ratios), min(ratios), max(ratios)


def main():
    cli = sys.argv[1] if len(sys.argv) > 1 else "phiq"
    sizes = [int(a) for a in sys.argv[2:]] or [1000, 10000]
    print(f"phiq {phiq.__version__}, one thread; median of 5 runs")
    for n in sizes:
        steps = 1000 if n <= 1000 else 200
        total, inside, ratio, lo, hi = measure(cli, n, steps)
        print(f"nfourbar N = {n:>6}, {steps} steps: Python {total * 1e3:8.1f} ms, inside run_sweep "
              f"{inside * 1e3:8.1f} ms, ratio {ratio:.3f} (runs {lo:.3f}–{hi:.3f})")


if __name__ == "__main__":
    main()
