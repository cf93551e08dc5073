#!/usr/bin/env python3
"""tools/simulate_batch_ranks.py against makespans worked out by hand (ctest simulate_batch_ranks)."""
import importlib.util
import json
import subprocess
import sys
import tempfile

spec = importlib.util.spec_from_file_location("simulate_batch_ranks", sys.argv[1])
sim = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sim)

failed = 0


def expect(what, got, want):
    global failed
    if abs(got - want) > 1e-12:
        print(f"simulate_batch_ranks: {what}: makespan {got}, expected {want}", file=sys.stderr)
        failed += 1


# (workers, costs, service, latency, dynamic makespan, static makespan)
cases = [
    (2, [1.0] * 4, 0.0, 0.0, 2.0, 2.0),  # equal cases share out evenly either way
    # one slow case first: static gives rank 0 cases 0–2 (4 + 1 + 1); dynamic lets rank 1 take cases 1–4 meanwhile
    (2, [4.0, 1.0, 1.0, 1.0, 1.0], 0.0, 0.0, 4.0, 6.0),
    # rank 0 is the bottleneck: both results arrive at t = 1 and are written one after the other (2 s each)
    (2, [1.0, 1.0], 2.0, 0.0, 5.0, 5.0),
    # one worker waits half a second for each answer: case 1 starts at 1.5 (static sends without waiting)
    (1, [1.0, 1.0], 0.0, 0.5, 2.5, 2.0),
    # the next case goes to the first worker whose result rank 0 has taken: worker 1 (t = 1) gets case 2, which
    # ends at 4; worker 0 ends case 0 at 3. Static: rank 0 has cases 0 and 1 (3 + 1), rank 1 case 2 (3).
    (2, [3.0, 1.0, 3.0], 0.0, 0.0, 4.0, 4.0),
]
for workers, costs, service, latency, dyn, sta in cases:
    expect(f"dynamic {workers} workers {costs}", sim.dynamic(workers, costs, service, latency), dyn)
    expect(f"static {workers} workers {costs}", sim.static(workers, costs, service), sta)

# the command: a summary of 4 cases, one of them 10× slower as a band of 25 % in the middle
with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
    json.dump({"results": [{"status": "success", "seconds": 1.0}] * 4 + [{"status": "failed", "seconds": 9.0}]}, f)
out = subprocess.run([sys.executable, sys.argv[1], f.name, "--slow", "0.25:10", "--ranks", "2"],
                     capture_output=True, text=True)
# costs [1, 1·10, 1, 1] (the band: case 1 of 4): static blocks {0,1} = 11, {2,3} = 2; dynamic: 10 on one worker,
# 1 + 1 + 1 on the other: 10. Total 13: efficiencies 13 / 22 and 13 / 20.
want = "| 2 | 11 s | 59.1% | 10 s | 65.0% |"
if out.returncode != 0 or want not in out.stdout:
    print(f"simulate_batch_ranks: command: expected the row '{want}', got:\n{out.stdout}{out.stderr}", file=sys.stderr)
    failed += 1
bad = subprocess.run([sys.executable, sys.argv[1], f.name, "--slow", "x"], capture_output=True, text=True)
if bad.returncode == 0 or "--slow: expected F:X" not in bad.stderr or len(bad.stderr.strip().splitlines()) != 1:
    print(f"simulate_batch_ranks: a bad --slow: expected one line and a non-zero exit, got {bad.stderr!r}",
          file=sys.stderr)
    failed += 1
sys.exit(1 if failed else 0)
