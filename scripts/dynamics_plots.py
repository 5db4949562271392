#!/usr/bin/env python3
"""Draws the physics checks of dynamic chains (docs/dynamics.md) from the CSV files that
examples/dynamics_plots writes: pendulum period error by amplitude, hanging chain mode error by
links, energy over 10 s, and the tip's path by sub-steps, as SVG files.

Usage: /usr/bin/python3 scripts/dynamics_plots.py CSV_FOLDER [OUT_FOLDER]
"""
import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

plt.rcParams.update({"svg.fonttype": "none", "font.size": 9, "svg.hashsalt": "flexkin"})
COLORS = {"overall": "#1f77b4", "shake": "#d62728", "tractrix": "#2ca02c", "dftl": "#ff7f0e"}


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def save(fig, out, name):
    fig.tight_layout()
    fig.savefig(out / name, metadata={"Date": None})
    plt.close(fig)
    print(out / name)


def main():
    folder = Path(sys.argv[1])
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else folder
    out.mkdir(parents=True, exist_ok=True)

    fig, ax = plt.subplots(figsize=(5, 3.2))
    series = defaultdict(list)
    for r in rows(folder / "pendulum_period.csv"):
        if r["projection"] in ("tractrix", "dftl"):
            continue  # one link: the same as overall
        series[(r["projection"], int(r["substeps"]))].append(
            (float(r["amplitude"]), float(r["relative_error"])))
    for (projection, substeps), points in sorted(series.items()):
        ax.semilogy(*zip(*points), color=COLORS[projection], marker="o", markersize=3,
                    linestyle="-" if substeps == 1 else "--",
                    label=f"{projection}{' = tractrix = dftl' if projection == 'overall' else ''},"
                          f" {substeps} sub-step{'s' if substeps > 1 else ''}")
    ax.set_xlabel("amplitude (rad)")
    ax.set_ylabel("period: relative error")
    ax.set_title("Pendulum at 60 Hz, 20 s")
    ax.legend(fontsize=7)
    save(fig, out, "dynamics_pendulum_period.svg")

    fig, ax = plt.subplots(figsize=(5, 3.2))
    series = defaultdict(list)
    for r in rows(folder / "hanging_modes.csv"):
        series[r["projection"]].append((int(r["links"]), float(r["relative_error"])))
    for projection, points in series.items():
        ax.loglog(*zip(*points), color=COLORS[projection], marker="o", label=projection)
    ax.set_xticks([32, 64, 128], ["32", "64", "128"])
    ax.set_xlabel("links")
    ax.set_ylabel("first mode: relative frequency error")
    ax.set_title("Hanging chain, 60 Hz, 4 sub-steps (SHAKE on 128: 16)")
    ax.legend(fontsize=7)
    save(fig, out, "dynamics_hanging_modes.svg")

    fig, ax = plt.subplots(figsize=(5, 3.2))
    data = rows(folder / "energy.csv")
    t = [float(r["time"]) for r in data]
    for projection in ("overall", "shake", "tractrix", "dftl"):
        ax.plot(t, [float(r[projection]) for r in data], color=COLORS[projection],
                label=projection, linewidth=1)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy (m g L / 2 = 4.9)")
    ax.set_title("8-link rope from horizontal, no damping, 16 sub-steps")
    ax.legend(fontsize=7)
    save(fig, out, "dynamics_energy.svg")

    fig, axes = plt.subplots(1, 4, figsize=(9, 2.8), sharey=True)
    series = defaultdict(list)
    for r in rows(folder / "tip_path.csv"):
        series[(r["projection"], int(r["substeps"]))].append((float(r["x"]), float(r["y"])))
    shades = {1: 0.8, 2: 0.6, 4: 0.4, 8: 0.2, 64: 0.0}
    for ax, projection in zip(axes, ("overall", "shake", "tractrix", "dftl")):
        for substeps, shade in shades.items():
            points = series[(projection, substeps)]
            ax.plot(*zip(*points), color=str(shade) if substeps < 64 else COLORS[projection],
                    linewidth=1, label=f"{substeps}")
        ax.set_title(projection)
        ax.set_aspect("equal")
        ax.set_xlabel("x")
    axes[0].set_ylabel("y")
    axes[0].legend(title="sub-steps", fontsize=6, title_fontsize=6)
    fig.suptitle("The rope's tip over 0.5 s, 60 Hz", fontsize=9)
    save(fig, out, "dynamics_tip_path.svg")


if __name__ == "__main__":
    main()
