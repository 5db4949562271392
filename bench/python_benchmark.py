"""The Python module against the C++ library, in one run (docs/BENCHMARKS.md, section 9).

The same four calls are timed from Python (flexkin, the module built in the tree) and from C++
(bench/python_baseline.cc, which calls the library directly), alternately, round after round,
each side in a fresh process every round:
  link_step   flexkin.tractrix_step of one 2D link, against TractrixStep
  move10      flexkin.Chain.move_leader of a 10-link chain, 8 sub-steps, against MoveLeader
  fig12       flexkin.run_scenario("examples/fig12_spatial_curve.json"), against
              LoadScenarioFile + Run
  chain10k    flexkin.run of a 10,000-link 3D chain, 200 leader steps, 4 sub-steps, every 10th
              frame recorded, against Run
The C++ runs record their frames as the module does, through Run's plain form into dense frames
(which the module wraps without a copy); the same runs streamed to a sink that copies each frame
into arrays allocated for the run are timed too and printed beside them.
For each call: the median time per call over the rounds in each language, the median of the
per-round ratios Python / C++, and the median per-round difference (the cost of going through
Python; for the two small calls, the call overhead). Targets (the Python module's issue): whole
runs within 5% of C++, call overhead at most 2 microseconds.

Run from the source directory, with the module and the baseline built in BUILD (default build):
  /usr/bin/python3 bench/python_benchmark.py [--build BUILD] [--rounds 7] [--samples 5]
"""
import argparse
import json
import math
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]


def per_call(call, samples):
    """Seconds per call, one value per sample; each sample repeats `call` so as to last about
    0.2 s (the repetitions chosen once, as python_baseline.cc does)."""
    reps = 1
    while True:
        start = time.perf_counter()
        for _ in range(reps):
            call()
        seconds = time.perf_counter() - start
        if seconds > 0.05:
            reps = max(1, int(reps * 0.2 / seconds))
            break
        reps *= 4
    result = []
    for _ in range(samples):
        start = time.perf_counter()
        for _ in range(reps):
            call()
        result.append((time.perf_counter() - start) / reps)
    return result


def python_cases(flexkin, np):
    """The Python side of each case: a function of no arguments, inputs made once."""
    head_old, head_new, tail = np.array([0.0, 0.0]), np.array([0.1, 0.05]), np.array([-1.0, 0.2])

    def link_step():
        flexkin.tractrix_step(head_old, head_new, tail, 1.0)

    chain = flexkin.Chain([[-0.25 * i, 0.0] for i in range(11)])
    targets = [np.array([0.2, 0.1]), np.array([0.0, 0.0])]
    which = [0]

    def move10():
        chain.move_leader(targets[which[0]], substeps=8)
        which[0] ^= 1

    fig12_path = str(ROOT / "examples" / "fig12_spatial_curve.json")

    def fig12():
        flexkin.run_scenario(fig12_path)

    # The formulas of python_baseline.cc's LongChain and LongChainSteps (same libm).
    points = np.array([[-0.01 * i, 0.0, 0.0] for i in range(10_001)])
    steps = np.array([[0.05 * k, 0.5 * math.sin(0.05 * k), 0.2 * (1.0 - math.cos(0.03 * k))]
                      for k in range(1, 201)])

    def chain10k():
        flexkin.run(points, steps, method="tractrix", substeps=4, record_every=10)

    return {"link_step": link_step, "move10": move10, "fig12": fig12, "chain10k": chain10k}


def machine():
    model = ""
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model or platform.processor()}, {os.cpu_count()} cores, Python {platform.python_version()}"


def format_seconds(s):
    return f"{s * 1e6:.3f} us" if s < 1e-3 else f"{s * 1e3:.2f} ms"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=str(ROOT / "build"))
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--samples", type=int, default=5)
    parser.add_argument("--json", help="also write the raw figures here")
    parser.add_argument("--worker", action="store_true",
                        help="time the Python side once and print it as JSON (used by the rounds)")
    args = parser.parse_args()

    build = pathlib.Path(args.build)
    sys.path.insert(0, str(build / "python"))
    import numpy as np
    import flexkin
    baseline = build / "bench" / "python_baseline"
    if not baseline.exists():
        sys.exit(f"python_benchmark: {baseline} is not built (cmake --build {build} "
                 "--target python_baseline)")
    cases = python_cases(flexkin, np)

    if args.worker:
        print(json.dumps({name: per_call(call, args.samples) for name, call in cases.items()}))
        return

    # Each round times both sides in fresh processes, the same way: one Python process (this
    # script with --worker) and one run of the C++ baseline, each timing the cases in turn.
    py = {name: [] for name in cases}
    cc = {name: [] for name in cases}
    worker = [sys.executable, __file__, "--worker", "--build", str(build),
              "--samples", str(args.samples)]
    for round_ in range(args.rounds):
        for command, into in ((worker, py),
                              ([str(baseline), str(ROOT / "examples"), str(args.samples)], cc)):
            out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
            for name, seconds in json.loads(out).items():
                into.setdefault(name, []).append(statistics.median(seconds))
        print(f"round {round_ + 1} of {args.rounds} done", file=sys.stderr, flush=True)

    print(f"machine: {machine()}")
    print(f"engine: FLEXKIN_SIMD={os.environ.get('FLEXKIN_SIMD', '(best available)')}; "
          f"{args.rounds} rounds x {args.samples} samples, medians")
    print(f"{'case':<10} {'Python':>12} {'C++':>12} {'Python/C++':>11} {'difference':>12}")
    rows = {}
    for name in cases:
        ratios = [p / c for p, c in zip(py[name], cc[name])]
        diffs = [p - c for p, c in zip(py[name], cc[name])]
        rows[name] = {"python": statistics.median(py[name]), "cpp": statistics.median(cc[name]),
                      "ratio": statistics.median(ratios), "difference": statistics.median(diffs),
                      "ratio_min": min(ratios), "ratio_max": max(ratios)}
        r = rows[name]
        print(f"{name:<10} {format_seconds(r['python']):>12} {format_seconds(r['cpp']):>12} "
              f"{r['ratio']:>11.3f} {format_seconds(r['difference']):>12}")
    for name in ("fig12", "chain10k"):
        sink = statistics.median(cc[name + "_sink"])
        rows[name]["cpp_sink"] = sink
        print(f"{name}: C++ run streamed to arrays by a sink "
              f"{format_seconds(sink)}, {rows[name]['python'] / sink:.3f} of it from Python")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": machine(), "rows": rows, "python": py, "cpp": cc}, f, indent=1)


if __name__ == "__main__":
    main()
