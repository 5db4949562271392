"""Paper Fig. 6 / Sec. 5.1 in Python: the C++ example examples/fig06_compare.cc, and a figure.

The parabola y = x^2 in 20 links of 0.25 pulled 0.7 at 45 degrees by four strategies
(sequential or overall, 5 steps of 0.14 or a single step; examples/fig06_*.json). The first
scenario, multi-step sequential, is the reference. Prints what fig06_compare prints, line for
line: the reference's L2 metric, then for each other scenario the distance of its final
configuration from the reference's (sum over points, arc-length weighted, largest) and its L2
metric. Draws the initial chain, every scenario's final chain and the leading and trailing ends'
paths into OUT/fig06_compare.png, and each point's distance from the reference.

Usage: PYTHONPATH=build/python python3 examples/python/fig06_compare.py [--out DIR]
           [REFERENCE.json OTHER.json...]   (default: the four examples/fig06_*.json; out/)
"""
import argparse
import os
import pathlib
import sys

import numpy as np

import flexkin

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENARIOS = ("fig06_parabola_multi_step.json", "fig06_parabola_single_step.json",
             "fig06_parabola_overall_multi_step.json", "fig06_parabola_overall_single_step.json")


def distances(result, reference):
    """Each point's distance from the reference's final configuration; the three sums."""
    gap = np.linalg.norm(result.frames[-1] - reference.frames[-1], axis=1)
    lengths = result.lengths
    left = np.concatenate([[0.0], lengths])    # the link before each point (none before point 0)
    right = np.concatenate([lengths, [0.0]])   # the link after it (none after the last)
    weighted = float(np.sum(0.5 * (left + right) * gap))
    return gap, float(gap.sum()), weighted, float(gap.max())


def compare(paths):
    """The runs of the scenarios and the lines fig06_compare prints for them."""
    results = [flexkin.run_scenario(p) for p in paths]
    reference = results[0]
    lines = [f"Fig. 6 / Sec. 5.1, reference {paths[0]}: L2 metric of the motion "
             f"{reference.metrics.l2_total:.6f}"]
    for path, result in zip(paths[1:], results[1:]):
        if result.frames.shape[1:] != reference.frames.shape[1:]:
            raise ValueError(f"{path}: a different chain than the reference")
        _, total, weighted, largest = distances(result, reference)
        lines.append(f"  {path} ({result.method}): distance from the reference: sum over points "
                     f"{total:.6f}, arc-length weighted {weighted:.6f}, largest {largest:.6f}; "
                     f"L2 metric of the motion {result.metrics.l2_total:.6f}")
    return results, lines


def draw(paths, results, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (shapes, zoom, gaps) = plt.subplots(1, 3, figsize=(15, 5.5),
                                             gridspec_kw={"width_ratios": [1, 1.6, 1.6]})
    first = results[0].frames[0]
    head = results[0].frames[:, 0]
    for axes in (shapes, zoom):
        axes.plot(first[:, 0], first[:, 1], "o-", color="0.7", ms=3, label="initial chain")
        axes.plot(head[:, 0], head[:, 1], "k-", lw=2, label="leading end's path")
    for path, result, color in zip(paths, results, ("C0", "C1", "C2", "C3")):
        name = pathlib.Path(path).stem.replace("fig06_parabola_", "")
        last = result.frames[-1]
        for axes in (shapes, zoom):
            axes.plot(last[:, 0], last[:, 1], ".-", color=color, label=f"{name} ({result.method})")
        shapes.plot(result.frames[:, -1, 0], result.frames[:, -1, 1], ":", color=color)
        if result is not results[0]:
            gap = distances(result, results[0])[0]
            gaps.plot(np.arange(len(gap)), gap, "o-", color=color, ms=3, label=name)
    shapes.set_aspect("equal")
    shapes.set_title("final chains (dotted: trailing end's path)", fontsize=10)
    zoom.set_xlim(-0.1, 1.4)
    zoom.set_ylim(-0.1, 1.2)
    zoom.set_aspect("equal")
    zoom.set_title("near the leading end", fontsize=10)
    zoom.legend(fontsize=7, loc="upper left")
    gaps.set_xlabel("point (0 = leading end)")
    gaps.set_ylabel("distance from the reference's final point")
    gaps.set_title(f"distance from {pathlib.Path(paths[0]).stem}", fontsize=10)
    gaps.legend(fontsize=7)
    fig.suptitle("Fig. 6 / Sec. 5.1: the parabola pulled 0.7 at 45 degrees")
    fig.tight_layout()
    os.makedirs(out_dir, exist_ok=True)
    target = os.path.join(out_dir, "fig06_compare.png")
    fig.savefig(target, dpi=100)
    plt.close(fig)
    return target


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenarios", nargs="*", help="REFERENCE.json OTHER.json...")
    parser.add_argument("--out", default="out", help="directory for the figure (default out/)")
    args = parser.parse_args(argv)
    paths = args.scenarios or [os.path.relpath(ROOT / "examples" / s) for s in SCENARIOS]
    if len(paths) < 2:
        parser.error("give a reference scenario and at least one other")
    try:
        results, lines = compare(paths)
    except (OSError, ValueError) as e:
        print(e, file=sys.stderr)
        return 1
    print("\n".join(lines))
    print(f"figure: {draw(paths, results, args.out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
