"""Two builds of the Python module against each other, in one sitting (docs/BENCHMARKS.md,
section 14): flexkin.run of a 2000-link 2D chain (400 leader steps, every frame recorded: 12.8 MB
of frames), flexkin.read_result of its .npz file and Result.write of it, each call the median of
5, in a fresh process per build per round, the builds alternately.

Prints, per call, each build's median over the rounds and the median and range of the per-round
ratio second / first.
  /usr/bin/python3 bench/python_builds.py BEFORE_BUILD AFTER_BUILD [--rounds 5]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def worker(python_dir):
    sys.path.insert(0, python_dir)
    import numpy as np
    import flexkin
    n, m = 2000, 400
    points = np.column_stack([-np.arange(n + 1) * 0.01, np.zeros(n + 1)])
    steps = np.column_stack([np.linspace(0.002, 0.8, m), 0.3 * np.sin(np.linspace(0, 3, m))])

    def timed(call, k=5):
        seconds = []
        for _ in range(k):
            start = time.perf_counter()
            call()
            seconds.append(time.perf_counter() - start)
        return statistics.median(seconds)

    out = tempfile.mkdtemp()
    result = flexkin.run(points, steps)
    path = os.path.join(out, "r.npz")
    result.write(path)
    print(json.dumps({"run": timed(lambda: flexkin.run(points, steps)),
                      "read_npz": timed(lambda: flexkin.read_result(path)),
                      "write_npz": timed(lambda: result.write(os.path.join(out, "w.npz")))}))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker)
        return
    sides = {"before": [], "after": []}
    for _ in range(args.rounds):
        for side in sides:
            build = getattr(args, side)
            out = subprocess.run([sys.executable, __file__, args.before, args.after, "--worker",
                                  os.path.join(build, "python")],
                                 check=True, capture_output=True, text=True).stdout
            sides[side].append(json.loads(out))
    for call in ("run", "read_npz", "write_npz"):
        before = [r[call] for r in sides["before"]]
        after = [r[call] for r in sides["after"]]
        ratios = [a / b for a, b in zip(after, before)]
        print(f"{call:10} before {statistics.median(before) * 1e3:8.1f} ms  after "
              f"{statistics.median(after) * 1e3:8.1f} ms  after/before {statistics.median(ratios):.3f}"
              f" ({min(ratios):.3f}-{max(ratios):.3f})")


if __name__ == "__main__":
    main()
