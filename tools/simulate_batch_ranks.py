#!/usr/bin/env python3
"""How `mpirun -np K phiq batch` would scale on more ranks than this machine has, by replaying its schedule.

`phiq batch` on MPI ranks (tools/cli/batch_ranks.hpp) hands out cases one at a time: a worker sends rank 0 its last
case's rows and gets its next case in the same exchange; rank 0 writes every case's rows itself, one message at a
time. This script replays that policy (dynamic) and, for comparison, a static split of the cases into K
contiguous blocks (each rank sweeps its block and sends its cases' rows to rank 0 without waiting for an answer),
with

- per-case costs measured on this machine: the `seconds` of every written case in a one-file batch's --summary
  (its set-up, sweep and rows on one thread), repeated in order up to --cases;
- near-singular cases: --slow F:X makes a fraction F of the cases, one contiguous band of parameter values (the
  middle of the list, as a sweep of a design parameter passes near a singular position), cost X times more;
- rank 0's time per case (--service: receiving and writing its rows, measured as the batch's `write` and message
  time per case) and the round trip of an exchange (--latency).

Efficiency = total case time / (workers × makespan). It assumes every rank is as fast as this machine's core and
that the file system takes rank 0's writes at the measured rate: a bound on what the schedule loses, not a
prediction of a cluster.

    tools/simulate_batch_ranks.py SUMMARY.json [--cases 100000] [--slow 0.05:10] [--service 2e-5]
                                               [--latency 2e-5] [--ranks 64,256,1024,4096]
"""
import argparse
import heapq
import json
import sys


def dynamic(workers, costs, service, latency):
    """Makespan when rank 0 hands out cases one at a time (the first `workers` cases start at t = 0)."""
    n = len(costs)
    events = []  # (time a worker's result reaches rank 0, worker)
    nxt = 0
    for w in range(min(workers, n)):
        heapq.heappush(events, (costs[nxt], w))
        nxt += 1
    server_free = 0.0
    while events:
        arrival, w = heapq.heappop(events)
        served = max(arrival, server_free) + service  # rank 0 takes messages one at a time, in arrival order
        server_free = served
        if nxt < n:
            heapq.heappush(events, (served + latency + costs[nxt], w))
            nxt += 1
    return server_free


def static(workers, costs, service):
    """Makespan when case i goes to rank floor(i·K/N) and each rank sweeps its block in order."""
    n = len(costs)
    arrivals = []
    clocks = [0.0] * workers
    for i, c in enumerate(costs):
        w = i * workers // n
        clocks[w] += c
        arrivals.append(clocks[w])
    server_free = 0.0
    for a in sorted(arrivals):
        server_free = max(a, server_free) + service
    return server_free


def case_costs(summary_path, cases, slow):
    with open(summary_path, encoding="utf-8") as f:
        summary = json.load(f)
    measured = [r["seconds"] for r in summary.get("results", []) if r.get("status") == "success" and "seconds" in r]
    if not measured:
        sys.exit(f"simulate_batch_ranks: {summary_path}: no written case with its `seconds` (a one-file batch's --summary)")
    n = cases or len(measured)
    costs = [measured[i % len(measured)] for i in range(n)]
    if slow:
        fraction, factor = slow
        band = int(round(fraction * n))
        start = (n - band) // 2
        for i in range(start, start + band):
            costs[i] *= factor
    return costs


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("summary", help="a one-file `phiq batch --summary` JSON (each case's seconds)")
    p.add_argument("--cases", type=int, default=0, help="cases to schedule (the measured ones repeated; 0: as measured)")
    p.add_argument("--slow", default="", help="F:X, a band of a fraction F of the cases costing X times more")
    p.add_argument("--service", type=float, default=0.0, help="rank 0's seconds per case (receive and write)")
    p.add_argument("--latency", type=float, default=0.0, help="seconds of an exchange's round trip")
    p.add_argument("--ranks", default="64,256,1024,4096", help="rank counts, one worker each")
    a = p.parse_args()
    slow = None
    if a.slow:
        try:
            f, x = (float(v) for v in a.slow.split(":"))
        except ValueError:
            sys.exit(f"simulate_batch_ranks: --slow: expected F:X (e.g. 0.05:10), got '{a.slow}'")
        slow = (f, x)
    try:
        ranks = [int(r) for r in a.ranks.split(",")]
    except ValueError:
        sys.exit(f"simulate_batch_ranks: --ranks: expected a comma-separated list of counts, got '{a.ranks}'")
    costs = case_costs(a.summary, a.cases, slow)
    total = sum(costs)
    print(f"{len(costs)} cases, {total:.3f} s of case time (mean {total / len(costs) * 1e3:.3f} ms"
          f"{', a band of %g %% at %g×' % (100 * slow[0], slow[1]) if slow else ''}), "
          f"rank 0 {a.service * 1e6:.1f} µs per case, round trip {a.latency * 1e6:.1f} µs")
    print("| ranks | static makespan | static efficiency | dynamic makespan | dynamic efficiency |")
    print("| ---: | ---: | ---: | ---: | ---: |")
    for k in ranks:
        s = static(k, costs, a.service)
        d = dynamic(k, costs, a.service, a.latency)
        print(f"| {k} | {s:.4g} s | {total / (k * s):.1%} | {d:.4g} s | {total / (k * d):.1%} |")


if __name__ == "__main__":
    main()
