#!/usr/bin/python3
"""A snake robot threads a field of 20 vertical pegs, its head on a planned slalom (issue 26).

The robot is examples/snake_robot_16.urdf: 16 modules of 0.1 m, each a collision cylinder of
radius 0.03 m, joined by yaw joints within +-0.8 rad. A snake robot's head leads and its body
follows: a chain run (flexkin run), not a fixed-base arm. The URDF gives the link lengths, the
link radius and the joint limits; the pegs and the head's path are those of
examples/snake_pegs.json (pegs of radius 0.3 at x = 1..20, the slalom y = 0.5 sin(pi (x - 0.5))).
The snake crawls in the plane z = 0, where each vertical peg is a disc: a "sphere" of the 2D
scenario form, which is exact for a vertical cylinder or capsule cut by that plane.

Two modes, two scenarios written to the output folder and run by the command line:
  tractrix     the pegs as colliders: every link whose tractrix step would enter a peg slides
               round it (the least motion that keeps it outside);
  follow_path  every joint on the head's path; the pegs are measured, not avoided.

Then the points of every frame are turned into joint angles (flexkin.joint_angles_from_points on
the URDF's model, checked against the angles computed here with numpy), the joint limits are
checked, and the least clearance of the body from the pegs per step (computed here, from the
frames: segment-to-disc distances less the link radius) is drawn for both modes.

Run from the repository root, after building the command line and the Python module:
    PYTHONPATH=build/python /usr/bin/python3 scripts/snake_robot_demo.py [--build build] [--out out/snake_robot]
"""

import argparse
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_urdf(path):
    """Link lengths, link radii and joint limits of a serial yaw-joint URDF, tail first."""
    robot = ET.parse(path).getroot()
    links = {link.get("name"): link for link in robot.findall("link")}
    joints = robot.findall("joint")
    child_of = {j.find("parent").get("link"): j for j in joints}
    # Walk from the root link (a parent of no joint's child) down the chain.
    children = {j.find("child").get("link") for j in joints}
    link = next(name for name in links if name not in children)
    origins, radii, lower, upper, names = [], [], [], [], []
    position = np.zeros(3)
    while link in child_of:
        joint = child_of[link]
        xyz = joint.find("origin").get("xyz", "0 0 0").split()
        position = position + np.array([float(v) for v in xyz])
        link = joint.find("child").get("link")
        if joint.get("type") == "fixed":
            origins.append(position.copy())  # the nose: the end of the last module
            continue
        origins.append(position.copy())
        names.append(joint.get("name"))
        limit = joint.find("limit")
        if joint.get("type") == "continuous" or limit is None:
            lower.append(-math.inf)
            upper.append(math.inf)
        else:
            lower.append(float(limit.get("lower")))
            upper.append(float(limit.get("upper")))
        radius = 0.0
        for cylinder in links[link].iter("cylinder"):
            radius = max(radius, float(cylinder.get("radius")))
        for sphere in links[link].iter("sphere"):
            radius = max(radius, float(sphere.get("radius")))
        radii.append(radius)
    origins = np.array(origins)
    lengths = np.linalg.norm(np.diff(origins, axis=0), axis=1)
    return {"lengths": lengths, "radii": np.array(radii), "lower": np.array(lower),
            "upper": np.array(upper), "names": names}


def scenario(pegs_file, robot, method):
    """The chain scenario: the snake of the URDF's links lying behind the slalom's start."""
    with open(pegs_file) as f:
        base = json.load(f)
    start = np.array(base["curve"]["start"], dtype=float)
    direction = np.array(base["curve"]["direction"], dtype=float)
    direction /= np.linalg.norm(direction)
    # Head first (chain order): the head at the start, the body trailing along `direction`.
    offsets = np.concatenate([[0.0], np.cumsum(robot["lengths"][::-1])])
    points = [list(start + s * direction) for s in offsets]
    radius = float(robot["radii"].max())
    return {
        "name": "snake_robot_16_" + method,
        "description": "examples/snake_robot_16.urdf threading the pegs of examples/snake_pegs.json "
                       "(links capsules of radius %g), method %s; written by "
                       "scripts/snake_robot_demo.py" % (radius, method),
        "curve": {"points": points},
        "leader": base["leader"],
        "method": method,
        "colliders": base["colliders"],
        "link_radius": radius,
        "record": {"every": 1},
    }


def segment_disc_clearance(a, b, centres, radius):
    """Least distance of segments [a_k, b_k] (k links) to disc centres (m pegs), less radius."""
    d = b - a  # (k, 2)
    rel = centres[None, :, :] - a[:, None, :]  # (k, m, 2)
    t = np.clip(np.einsum("kmd,kd->km", rel, d) / np.einsum("kd,kd->k", d, d)[:, None], 0, 1)
    nearest = a[:, None, :] + t[..., None] * d[:, None, :]
    return np.linalg.norm(centres[None] - nearest, axis=2) - radius  # (k, m)


def angles_numpy(points_tail_first):
    """Planar joint angles: joint 0 the heading from +x, joint j the turn from link j to j+1."""
    d = np.diff(points_tail_first, axis=0)
    heading = np.arctan2(d[:, 1], d[:, 0])
    turns = np.diff(np.concatenate([[0.0], heading]))
    return np.mod(turns + math.pi, 2 * math.pi) - math.pi


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default="build", help="the build folder (default build)")
    parser.add_argument("--out", default=os.path.join("out", "snake_robot"))
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    urdf = os.path.join(ROOT, "examples", "snake_robot_16.urdf")
    robot = read_urdf(urdf)
    n = len(robot["lengths"])
    link_radius = float(robot["radii"].max())
    print("URDF: %d modules, links %s m, link radius %g m, joint limits %s rad" %
          (n, np.unique(robot["lengths"].round(12)), link_radius,
           np.unique(np.abs(robot["upper"][np.isfinite(robot["upper"])]))))
    try:
        import flexkin
        model = flexkin.arm_from_urdf(urdf)
    except ImportError:
        flexkin, model = None, None
        print("flexkin Python module not found (PYTHONPATH=build/python): angles from numpy only")

    pegs_file = os.path.join(ROOT, "examples", "snake_pegs.json")
    with open(pegs_file) as f:
        pegs = json.load(f)["colliders"]
    centres = np.array([p["center"] for p in pegs], dtype=float)
    peg_radius = np.array([p["radius"] for p in pegs], dtype=float)
    cli = os.path.join(args.build, "apps", "flexkin")
    curves = {}
    ok = True
    for method in ("tractrix", "follow_path"):
        path = os.path.join(args.out, "snake_robot_16_%s.json" % method)
        with open(path, "w") as f:
            json.dump(scenario(pegs_file, robot, method), f, indent=1)
        result_file = os.path.join(args.out, "snake_robot_16_%s_result.json" % method)
        subprocess.run([cli, "run", path, "-o", result_file], check=True)
        with open(result_file) as f:
            frames = json.load(f)["frames"]
        clearance, worst_joint, beyond = [], 0.0, 0
        max_angle_gap = 0.0
        for frame in frames:
            p = np.array(frame["points"], dtype=float)
            c = segment_disc_clearance(p[:-1], p[1:], centres, 0.0) - peg_radius[None] \
                - link_radius
            clearance.append(c.min())
            tail_first = p[::-1]
            angles = angles_numpy(tail_first)
            if model is not None:
                lib, _ = flexkin.joint_angles_from_points(model, tail_first - tail_first[0])
                gap = np.abs(np.mod(lib - angles + math.pi, 2 * math.pi) - math.pi).max()
                max_angle_gap = max(max_angle_gap, gap)
            inner = np.abs(angles[1:])  # joint 0 is the heading (continuous)
            worst_joint = max(worst_joint, inner.max())
            beyond += int(np.sum((angles < robot["lower"] - 1e-9) | (angles > robot["upper"] + 1e-9)))
        curves[method] = np.array(clearance)
        print("%-11s %d frames: least clearance %.4f m (step %d), largest joint angle %.3f rad "
              "(limit %.3f), joint values beyond their limits: %d%s" %
              (method, len(frames), curves[method].min(), int(curves[method].argmin()),
               worst_joint, robot["upper"][1], beyond,
               (", library vs numpy angles within %.1e rad" % max_angle_gap)
               if model is not None else ""))
        ok &= beyond == 0

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 3.6))
    for method, style in (("tractrix", "-"), ("follow_path", "--")):
        ax.plot(curves[method], style, label=method)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("leader step")
    ax.set_ylabel("least clearance (m)")
    ax.set_title("snake_robot_16 among 20 pegs: body capsules (r = %g m) to pegs" % link_radius)
    ax.legend()
    fig.tight_layout()
    figure = os.path.join(args.out, "snake_robot_16_clearance.png")
    fig.savefig(figure, dpi=120)
    print("figure:", figure)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
