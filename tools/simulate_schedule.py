#!/usr/bin/env python3
"""Speed-up of a parallel sweep on more cores than this machine has, by simulating phiq's schedule.

run_sweep (engine/src/sweep/parallel_sweep.cpp) runs `threads` loops that take, in this order of preference: the next seed when
fewer chunks are ready than threads; else the lowest ready chunk; else the next seed; else wait. Seeds are found
one at a time, in order. This script replays that policy with durations measured on this machine by
`BM_NFourBarParallelSweep` (bench/results/engine.json):

- a chunk takes (1-thread sweep time / steps) · (its steps + 1 + start) — its steps (`chunk`, fewer in the last),
  its seam step (not the last) and the start from its seed (not chunk 0), which costs about `start` steps more (a
  fresh factorisation and no predictor history);
- a seed takes (seed_share · 2-thread time) / (number of seeds).

It assumes that the memory system keeps up with every core (measured here: two independent sweeps run 1.6–2.0×
as fast as one, `pair_throughput`), so it is a bound on what the schedule loses, not a prediction of a machine.

    tools/simulate_schedule.py bench/results/engine.json [--steps 1000] [--chunk 64] [--start 1]
"""
import argparse
import heapq
import json
import math
import sys


def simulate(threads, chunk_times, seed_time):
    """Makespan of the schedule: chunk 0 needs no seed; chunk c > 0 needs seed c (seeds in order)."""
    n_chunks = len(chunk_times)
    seeded, claimed, seeding_busy = 1, 0, False
    clock = 0.0
    idle = list(range(threads))
    events = []  # (time, kind, thread)
    done_chunks = 0
    while done_chunks < n_chunks:
        # give every idle thread work, by the engine's order of preference
        still_idle = []
        for t in idle:
            ready = seeded - claimed
            can_seed = not seeding_busy and seeded < n_chunks
            if can_seed and ready < threads:
                seeding_busy = True
                heapq.heappush(events, (clock + seed_time, "seed", t))
            elif ready > 0:
                heapq.heappush(events, (clock + chunk_times[claimed], "chunk", t))
                claimed += 1
            elif can_seed:
                seeding_busy = True
                heapq.heappush(events, (clock + seed_time, "seed", t))
            else:
                still_idle.append(t)
        idle = still_idle
        clock, kind, t = heapq.heappop(events)
        if kind == "seed":
            seeded += 1
            seeding_busy = False
        else:
            done_chunks += 1
        idle.append(t)
        # waiting threads wake on every event (the engine's condition variable)
    return clock


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json", help="Google Benchmark JSON with BM_NFourBarParallelSweep rows")
    ap.add_argument("--steps", type=int, default=1000, help="steps of the sweep (the benchmark's: 1000)")
    ap.add_argument("--chunk", type=int, default=64, help="steps per chunk (the engine's default: 64)")
    ap.add_argument("--start", type=float, default=1.0, help="extra cost of a chunk's start, in steps")
    ap.add_argument("--threads", default="1,2,4,8,16,32", help="thread counts to simulate")
    a = ap.parse_args()
    rows = [b for b in json.load(open(a.json))["benchmarks"] if b["name"].startswith("BM_NFourBarParallelSweep")]
    if not rows:
        sys.exit(f"{a.json}: no BM_NFourBarParallelSweep rows")
    counts = [int(x) for x in a.threads.split(",")]
    n_chunks = math.ceil(a.steps / a.chunk)
    print("| nfourbar N | measured 2-thread speed-up | " + " | ".join(f"{p} threads" for p in counts) + " |")
    print("| ---: | ---: | " + " | ".join("---:" for _ in counts) + " |")
    for b in rows:
        n = b["name"].split("N:")[1].split("/")[0]
        t1 = b["one_thread_ms"]
        step = t1 / a.steps
        chunk_times = []
        for c in range(n_chunks):
            steps = min(a.chunk, a.steps - c * a.chunk)
            chunk_times.append(step * (steps + (1 if c + 1 < n_chunks else 0) + (a.start if c > 0 else 0)))
        seed_time = b["seed_share"] * b["two_threads_ms"] / max(1, n_chunks - 1)
        speedups = [t1 / simulate(p, chunk_times, seed_time) if p > 1 else 1.0 for p in counts]
        print(f"| {n} | {b['speedup']:.2f} | " + " | ".join(f"{s:.2f}" for s in speedups) + " |")


if __name__ == "__main__":
    main()
