"""An 8-link planar arm whose end effector tracks a circle, in Python: `flexkin robot` on
examples/robot_planar_8link.json, with the arm's poses and its joint angles drawn.

A fixed-base arm of 8 links of 70 mm, joint limits +-1.2 rad, its end effector taken once round a
circle (centre (-0.2, 0.42), through its initial position) in 200 steps by the tractrix
(docs/robots.md). Prints the report `flexkin robot` prints, the largest distance of the end
effector from its targets, and per joint (the base first) the range of its angle, its largest
change in one step and its total travel: the motion dies out toward the base. Runs the same arm
built in code (flexkin.ArmModel, flexkin.track_path) and checks it gives the same angles. Writes
OUT/arm_circle.png (poses; joint angle against step) and OUT/arm_circle_joints.csv (as
`flexkin robot --csv`: step 0 the initial angles).

Usage: PYTHONPATH=build/python python3 examples/python/arm_circle.py [--out DIR]
           [robot.json]   (default examples/robot_planar_8link.json; out/)
"""
import argparse
import json
import os
import pathlib
import sys

import numpy as np

import flexkin

ROOT = pathlib.Path(__file__).resolve().parents[2]


def arm_in_code(path):
    """The scenario's arm and solver as flexkin.ArmModel and ArmOptions (docs/python.md), and
    its joint limits: the same arm built in code."""
    with open(path) as f:
        spec = json.load(f)
    arm, solver = spec["arm"], spec.get("solver", {})
    links = arm["links"]
    model = flexkin.ArmModel([arm["link_length"]] * links, dim=arm["dim"], base=arm["base"],
                             base_direction=arm["base_direction"],
                             joint_min=[arm["joint_limits"]["min"]] * links,
                             joint_max=[arm["joint_limits"]["max"]] * links,
                             initial_angles=arm["initial_angles"])
    limits = (arm["joint_limits"]["min"], arm["joint_limits"]["max"])
    return model, flexkin.ArmOptions(**solver), limits


def joint_table(traj):
    """All joint angles, step 0 the initial ones; per joint: range, largest step, travel."""
    angles = np.vstack([traj.initial_angles, traj.angles])
    change = np.abs(np.diff(angles, axis=0))
    return angles, angles.max(axis=0) - angles.min(axis=0), change.max(axis=0), change.sum(axis=0)


def draw(traj, angles, limits, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (poses, joints) = plt.subplots(1, 2, figsize=(13, 5.5))
    every = max(1, traj.num_steps // 20)
    colors = plt.cm.viridis(np.linspace(0, 1, len(range(0, traj.num_steps, every))))
    for color, i in zip(colors, range(0, traj.num_steps, every)):
        poses.plot(traj.points[i, :, 0], traj.points[i, :, 1], ".-", color=color, lw=1, ms=4)
    start = traj.initial_points
    poses.plot(start[:, 0], start[:, 1], "o-", color="k", lw=2, ms=4, label="initial pose")
    poses.plot(traj.path[:, 0], traj.path[:, 1], "-", color="C3", lw=2, label="targets (circle)")
    poses.plot(*traj.base, "ks", ms=10, zorder=5, label="base")
    poses.set_aspect("equal")
    poses.set_title(f"every {every}th pose (dark: early, light: late)", fontsize=10)
    poses.legend(fontsize=8, loc="lower left")
    steps = np.arange(len(angles))
    for j in range(angles.shape[1]):
        name = " (base)" if j == 0 else " (end effector's link)" if j == angles.shape[1] - 1 else ""
        joints.plot(steps, angles[:, j], color=plt.cm.plasma(0.9 * j / (angles.shape[1] - 1)),
                    label=f"joint {j}{name}")
    for limit in limits:
        joints.axhline(limit, color="0.5", ls=":", lw=1)
    joints.set_xlabel("step (0: initial angles; dotted: the joint limits)")
    joints.set_ylabel("joint angle (rad)")
    joints.set_title("joint angles: the motion dies out toward the base", fontsize=10)
    joints.legend(fontsize=7, ncol=2)
    fig.suptitle(traj.scenario)
    fig.tight_layout()
    os.makedirs(out_dir, exist_ok=True)
    target = os.path.join(out_dir, "arm_circle.png")
    fig.savefig(target, dpi=100)
    plt.close(fig)
    return target


def write_csv(angles, out_dir):
    target = os.path.join(out_dir, "arm_circle_joints.csv")
    with open(target, "w") as f:
        f.write("step," + ",".join(f"joint_{j}" for j in range(angles.shape[1])) + "\n")
        for i, row in enumerate(angles):
            f.write(f"{i}," + ",".join(f"{a:.17g}" for a in row) + "\n")
    return target


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenario", nargs="?",
                        default=os.path.relpath(ROOT / "examples" / "robot_planar_8link.json"))
    parser.add_argument("--out", default="out", help="directory for the plot (default out/)")
    args = parser.parse_args(argv)
    try:
        traj = flexkin.run_robot(args.scenario)
        model, options, limits = arm_in_code(args.scenario)
    except (OSError, ValueError, KeyError) as e:
        print(f"{args.scenario}: {e}", file=sys.stderr)
        return 1
    print(traj.brief_report())
    print(f"largest distance of the end effector from its target: {traj.max_ee_error:.3g} "
          f"(every target reached: {traj.unreached == 0})")
    angles, span, largest, travel = joint_table(traj)
    print("joint   range (rad)   largest step (rad)   travel (rad)")
    for j in range(len(span)):
        name = "  base" if j == 0 else "  end effector's link" if j == len(span) - 1 else ""
        print(f"{j:5d}   {span[j]:11.6f}   {largest[j]:18.6f}   {travel[j]:12.6f}{name}")
    print(f"range at the base {span[0]:.3f} rad, at the end effector's link {span[-1]:.3f} rad")
    again = flexkin.track_path(model, traj.path, options=options)
    same = np.array_equal(again.angles, traj.angles) and np.array_equal(again.points, traj.points)
    print(f"the same arm in code (flexkin.ArmModel, flexkin.track_path): "
          f"{'identical joint angles' if same else 'DIFFERENT joint angles'}")
    os.makedirs(args.out, exist_ok=True)
    print(f"joint angles: {write_csv(angles, args.out)}")
    print(f"figure: {draw(traj, angles, limits, args.out)}")
    return 0 if same and traj.unreached == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
