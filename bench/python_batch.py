#!/usr/bin/python3
"""phiq.run_batch against `phiq batch`: the 2 000-case crank-slider batch of bench/README.md ("Batches": L2 and L3 on
a 40 × 50 grid within ±3 % of 0.3 and 1.0, 181 rows of q, q̇, q̈ each, 362 000 steps), from Python into memory
against the whole CLI command writing one CSV, and run_batch with the sensitivities to both lengths, on 1 and 2
threads.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_batch.py build/tools/phiq [RUNS]

Prints one line per thread count: the median wall time of RUNS runs (default 5) of each, with their min–max, and
the steps a second of the medians."""
import os
import statistics
import subprocess
import sys
import tempfile
import time

import phiq

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "models", "seed", "crank_slider_mixed.yaml")


def cases():
    return {"L2": [0.3 * (1 + 0.03 * ((k % 40) / 19.5 - 1)) for k in range(2000)],
            "L3": [1.0 * (1 + 0.03 * ((k // 40) / 24.5 - 1)) for k in range(2000)]}


def timed(runs, work):
    seconds = []
    for _ in range(runs):
        start = time.perf_counter()
        work()
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds), min(seconds), max(seconds)


def main():
    cli = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else "phiq"  # (the command runs in a scratch folder)
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    values = cases()
    steps = 2000 * 181
    print(f"phiq {phiq.__version__}: 2 000 crank-slider cases × 181 rows; median (min–max) of {runs} runs")
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "cases.csv"), "w") as f:
            f.write("L2,L3\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(values["L2"], values["L3"])))
        for threads in (1, 2):
            def python():
                batch = phiq.run_batch(phiq.load_scene(SCENE), values, threads=threads)
                assert batch.ok and batch["xB"].shape == (2000, 181)

            def command():
                subprocess.run([cli, "batch", "-q", SCENE, "cases.csv", "-o", "all.csv", "--threads", str(threads)],
                               cwd=tmp, check=True)
            def sensitivities():  # ∂q/∂p, ∂q̇/∂p, ∂q̈/∂p along both lengths, at each case's own values
                batch = phiq.run_batch(phiq.load_scene(SCENE), values, threads=threads, sensitivities=["L2", "L3"])
                assert batch.ok and batch.sensitivity("L3").shape == (2000, 181, 4)

            for name, work in (("run_batch", python), ("phiq batch", command), ("+ ∂/∂L2, L3", sensitivities)):
                med, lo, hi = timed(runs, work)
                print(f"{threads} thread{'s' if threads > 1 else ' '} {name:>11}: {med:.3f} s ({lo:.3f}–{hi:.3f}), "
                      f"{steps / med:,.0f} steps/s")


if __name__ == "__main__":
    main()
