#!/usr/bin/env python3
"""tools/simulate_schedule.py against makespans worked out by hand (ctest simulate_schedule)."""
import importlib.util
import sys

spec = importlib.util.spec_from_file_location("simulate_schedule", sys.argv[1])
sim = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sim)

cases = [
    # (threads, chunk times, seed time, makespan)
    (1, [1.0] * 4, 0.0, 4.0),        # one thread runs everything in turn
    (2, [1.0] * 4, 0.0, 2.0),        # free seeds: four equal chunks on two threads
    (2, [1.0] * 3, 0.0, 2.0),        # an odd chunk leaves one thread idle at the end
    (4, [1.0] * 8, 1.0, 8.0),        # seeds as slow as chunks: chunk c starts when seed c is found, at t = c
    # chunk 0 on one thread (to t = 3); the other seeds 1 and 2 (to t = 1), runs chunk 1, seeds 3 (the seeding
    # goes first while fewer chunks are ready than threads), runs chunk 2 (to 3.5); chunk 3 follows chunk 0: 4
    (2, [3.0, 1.0, 1.0, 1.0], 0.5, 4.0),
]
failed = 0
for threads, chunks, seed, expected in cases:
    got = sim.simulate(threads, chunks, seed)
    if abs(got - expected) > 1e-12:
        print(f"simulate({threads}, {chunks}, {seed}) = {got}, expected {expected}")
        failed += 1
sys.exit(1 if failed else 0)
