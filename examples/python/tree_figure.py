"""Trees (docs/trees.md): a figure of a tree result, and the passes each frame took.

Reads a tree result written by `flexkin run` of a tree scenario (examples/tree_two_arms.json,
examples/tree_plant.json) with numpy alone and draws, with matplotlib, two panels: the tree at a
few frames (every link, from the parents; seen along the axis given by --view, z for a 3D tree
by default: x across, y up; y: x across, z up), darker for later frames, the driven points' paths
in red; and the passes each frame took with the residual it ended with (a tree driven at one
point takes no passes). Writes NAME.png beside the result, or to --out.

Run: /usr/bin/python3 examples/python/tree_figure.py out/tree_two_arms.npz
"""
import argparse
import json
import pathlib
import zipfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("result", type=pathlib.Path)
    parser.add_argument("--out", type=pathlib.Path, default=None)
    parser.add_argument("--view", choices=["z", "y"], default="z")
    parser.add_argument("--snapshots", type=int, default=6)
    args = parser.parse_args()
    data = np.load(args.result)
    info = json.loads(zipfile.ZipFile(args.result).read("tree.json"))
    frames, parents = data["frames"], data["parents"]
    across, up = (0, 1) if args.view == "z" or frames.shape[2] == 2 else (0, 2)

    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 5),
                                         gridspec_kw={"width_ratios": [3, 2]})
    chosen = np.linspace(0, len(frames) - 1, args.snapshots).round().astype(int)
    for order, f in enumerate(chosen):
        shade = 0.8 - 0.7 * order / max(1, len(chosen) - 1)
        for i, p in enumerate(parents):
            if p < 0:
                continue
            left.plot(frames[f, [p, i], across], frames[f, [p, i], up], color=str(shade), lw=1.2)
    for t in info["targets"]:
        left.plot(frames[:, t, across], frames[:, t, up], color="tab:red", lw=1)
    for t in info["fixed"]:
        left.plot(frames[0, t, across], frames[0, t, up], "ks", ms=6)
    left.set_aspect("equal")
    left.set_title(f"{info['name']}: {frames.shape[1]} points, {len(frames) - 1} frames "
                   f"({info['method']})")
    left.set_xlabel("xyz"[across])
    left.set_ylabel("xyz"[up])

    steps = np.arange(1, len(frames))
    right.bar(steps, data["passes"], color="tab:blue", width=1.0)
    right.set_xlabel("frame")
    right.set_ylabel("passes")
    twin = right.twinx()
    residual = np.maximum(data["residual"], 1e-17)
    twin.semilogy(steps, residual, color="tab:orange")
    twin.set_ylabel("residual (of the longest link)")
    right.set_title(f"link lengths within {info['max_length_error']:.1e}; "
                    f"{info['failures']} frames not reached")
    figure.tight_layout()
    out = args.out or args.result.with_suffix(".png")
    figure.savefig(out, dpi=120)
    print(f"{out}: {len(frames)} frames, at most {int(data['passes'].max())} passes, "
          f"residual at most {data['residual'].max():.2g}")


if __name__ == "__main__":
    main()
