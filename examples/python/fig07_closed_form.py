"""Paper Fig. 7 / eq. (23) in Python: the C++ example examples/fig07_closed_form.cc, and a plot.

A straight link whose leading end is pulled in a straight line, the trailing end initially
perpendicular to the pull (examples/fig07_straight_link.json). Runs the scenario and compares
every recorded trailing-end position with the closed form (the tractrix)
  x(p) = p - L tanh(p/L),  y(p) = L sech(p/L)
in the frame of the pull (x along the pull from the head's start, y toward the initial tail).
Prints the line fig07_closed_form prints and exits 1, as it does, if the largest distance is not
below 1e-12 link lengths. Plots the computed path on the closed form and the distance per frame
into OUT/fig07_closed_form.png.

Usage: PYTHONPATH=build/python python3 examples/python/fig07_closed_form.py [--out DIR]
           [scenario.json]   (default examples/fig07_straight_link.json; out/)
"""
import argparse
import math
import os
import pathlib
import sys

import numpy as np

import flexkin

ROOT = pathlib.Path(__file__).resolve().parents[2]


def closed_form(scenario_path):
    """The run, its trailing end's closed-form positions, the distances and the printed line."""
    scenario = flexkin.load_scenario(scenario_path)
    chain = scenario.chain
    if chain.num_links != 1:
        raise ValueError(f"{scenario_path}: expected one link, got {chain.num_links}")
    head0, tail0 = chain.points[0], chain.points[1]
    pull = scenario.leader_steps[-1] - head0
    u = pull / np.linalg.norm(pull)
    w = (tail0 - head0) / np.linalg.norm(tail0 - head0)
    if abs(u @ w) > 1e-12:
        raise ValueError(f"{scenario_path}: eq. (23) needs the link perpendicular to the pull")
    length = chain.lengths[0]
    result = flexkin.run_scenario(scenario)
    expected = np.empty_like(result.frames[:, 1])
    for i, head in enumerate(result.frames[:, 0]):
        p = np.linalg.norm(head - head0)   # how far the head has moved
        # math's tanh and cosh (the C library's, as the C++ example's), not numpy's vector ones
        expected[i] = head0 + (p - length * math.tanh(p / length)) * u + length / math.cosh(
            p / length) * w
    error = np.linalg.norm(result.frames[:, 1] - expected, axis=1) / length
    worst = float(error.max())
    line = (f"Fig. 7 (eq. 23): {len(result.frames)} frames, pull "
            f"{np.linalg.norm(pull) / length:.6g} link lengths; largest distance of the trailing "
            f"end from the closed form: {worst:.3g} link lengths; {result.brief_report()}")
    return result, expected, error, line


def draw(result, expected, error, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (path, gap) = plt.subplots(2, 1, figsize=(9, 7), gridspec_kw={"height_ratios": [1, 1.2]})
    tail = result.frames[:, 1]
    head = result.frames[:, 0]
    path.plot(head[:, 0], head[:, 1], "k-", lw=1, label="leading end (pulled)")
    path.plot(expected[:, 0], expected[:, 1], "-", color="C1", lw=4, alpha=0.5,
              label="closed form (tractrix, eq. 23)")
    path.plot(tail[::10, 0], tail[::10, 1], "o", color="C0", ms=3,
              label="computed trailing end (every 10th frame)")
    for i in range(0, len(head), 100):
        path.plot(result.frames[i, :, 0], result.frames[i, :, 1], "-", color="0.5", lw=1)
    path.set_aspect("equal")
    path.set_title("Fig. 7: the trailing end of a pulled link", fontsize=10)
    path.legend(fontsize=7, loc="upper left")
    exact = error == 0   # drawn at the bottom of the logarithmic axis
    gap.semilogy(result.steps[~exact], error[~exact], ".", ms=2)
    floor = error[~exact].min() / 10 if (~exact).any() else 1e-18
    gap.semilogy(result.steps[exact], np.full(exact.sum(), floor), "x", ms=4,
                 color="C2", label="exactly on the closed form")
    if exact.any():
        gap.legend(fontsize=7)
    gap.set_xlabel("leader step")
    gap.set_ylabel("distance from the closed form (link lengths)")
    gap.set_title("distance of the computed trailing end from the closed form", fontsize=10)
    fig.tight_layout()
    os.makedirs(out_dir, exist_ok=True)
    target = os.path.join(out_dir, "fig07_closed_form.png")
    fig.savefig(target, dpi=100)
    plt.close(fig)
    return target


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenario", nargs="?",
                        default=os.path.relpath(ROOT / "examples" / "fig07_straight_link.json"))
    parser.add_argument("--out", default="out", help="directory for the plot (default out/)")
    args = parser.parse_args(argv)
    try:
        result, expected, error, line = closed_form(args.scenario)
    except (OSError, ValueError) as e:
        print(f"{args.scenario}: {e}" if isinstance(e, OSError) else e, file=sys.stderr)
        return 1
    print(line)
    print(f"plot: {draw(result, expected, error, args.out)}")
    return 0 if error.max() < 1e-12 else 1


if __name__ == "__main__":
    sys.exit(main())
