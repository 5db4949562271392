"""Dynamic hair (docs/dynamics.md, "Strands"): the energy and the tips' paths of a strand file.

Reads a strand file written by `flexkin run` of a groom scenario with "dynamics" (for example
examples/groom_head_gravity.json) with numpy alone and draws, with matplotlib, two panels: the
strands' energy at every recorded frame (groom.json's report: kinetic plus potential, each
strand's free points weighing 1, summed over the strands) and the height of the tips of a few
strands over time, beside the body's turn. Writes NAME_dynamics.png beside the strand file, or to
the path given second.

Run: /usr/bin/python3 examples/python/hair_dynamics_plot.py out/groom_head_gravity.npz
"""
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(path, output=None):
    data = np.load(path)
    info = json.loads(bytes(data["groom.json"]).decode("utf-8"))
    if "dynamics" not in info:
        sys.exit(f"{path}: not a dynamic groom's strand file (no \"dynamics\" in groom.json)")
    times = data["times"]
    energy = np.array([math.nan if e is None else e for e in info["report"]["energy"]])
    offsets = data["offsets"]
    points = data["points"]  # (frames, points, dim)
    tips = offsets[1:] - 1
    chosen = np.linspace(0, len(tips) - 1, 8).astype(int)
    rotation = data["body_rotation"]  # (frames, 3, 3)
    yaw = np.degrees(np.arctan2(rotation[:, 1, 0], rotation[:, 0, 0]))

    figure, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    top.plot(times, energy, color="tab:blue")
    top.set_ylabel("energy (J per kg of hair)")
    top.set_title(f"{info['name']}: {info['num_strands']} strands, projection "
                  f"{info['dynamics']['projection']}, damping {info['dynamics']['damping']} /s")
    for s in chosen:
        bottom.plot(times, points[:, tips[s], 2], linewidth=1)
    bottom.set_ylabel("tip height (m)")
    bottom.set_xlabel("time (s)")
    turn = bottom.twinx()
    turn.plot(times, yaw, color="gray", linestyle="--", linewidth=1)
    turn.set_ylabel("head yaw (degrees, dashed)")
    figure.tight_layout()
    output = output or path.rsplit(".", 1)[0] + "_dynamics.png"
    figure.savefig(output, dpi=120)
    first = energy[1] if len(energy) > 1 else math.nan
    print(f"{output}: energy from {first:.4g} (frame 1) to {energy[-1]:.4g} (last frame)")


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: hair_dynamics_plot.py STRANDS.npz [OUTPUT.png]")
    main(*sys.argv[1:])
