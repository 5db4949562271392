"""Writes the two-armed robot example (docs/trees.md, "Robot trees"): its URDF,
examples/robot_two_arms.urdf (a torso turning on a fixed base, two 6-joint arms and a head that
pans and tilts: 15 revolute joints with limits), and its scenario,
examples/tree_robot_two_arms.json (the hands go from where they are to circles in front of the
robot over 30 frames and round them twice over 150; the camera on the head turns from straight
ahead to the left hand over the first 30 frames and watches it).

    /usr/bin/python3 examples/python/make_robot_two_arms.py [DIRECTORY]   (default: examples)
"""
import json
import math
import pathlib
import sys


def joint(name, kind, parent, child, xyz, axis=None, limits=None):
    text = (f'  <joint name="{name}" type="{kind}">\n    <parent link="{parent}"/>\n'
            f'    <child link="{child}"/>\n'
            f'    <origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="0 0 0"/>\n')
    if axis:
        text += f'    <axis xyz="{axis[0]} {axis[1]} {axis[2]}"/>\n'
    if limits:
        text += (f'    <limit lower="{limits[0]}" upper="{limits[1]}" effort="50" '
                 'velocity="3"/>\n')
    return text + '  </joint>\n'


def urdf():
    links = ["base_link", "torso", "head_pan", "head", "camera"]
    joints = [
        joint("waist", "revolute", "base_link", "torso", (0, 0, 0.5), (0, 0, 1), (-1.6, 1.6)),
        joint("neck_pan", "revolute", "torso", "head_pan", (0, 0, 0.7), (0, 0, 1), (-1.4, 1.4)),
        joint("neck_tilt", "revolute", "head_pan", "head", (0, 0, 0.08), (0, 1, 0), (-0.8, 0.8)),
        joint("camera_mount", "fixed", "head", "camera", (0.1, 0, 0.06)),
    ]
    for side, s in (("l", 1), ("r", -1)):
        names = [f"{side}_shoulder", f"{side}_upper_arm", f"{side}_upper_arm_twist",
                 f"{side}_forearm", f"{side}_wrist", f"{side}_hand", f"{side}_tool"]
        links += names
        # The upper arm out to the side, the forearm forward from the elbow, the hand beyond.
        # The shoulder raises the arm (about x), swings it forward (about z) and twists it
        # (about the arm, y): three axes square to each other at the zero pose, so that the
        # shoulder starts away from its gimbal lock (the arm pointing straight ahead).
        joints += [
            joint(f"{side}_shoulder_roll", "revolute", "torso", names[0], (0, s * 0.22, 0.55),
                  (1, 0, 0), (-2.0, 2.0)),
            joint(f"{side}_shoulder_yaw", "revolute", names[0], names[1], (0, s * 0.05, 0),
                  (0, 0, 1), (-1.4, 1.4)),
            joint(f"{side}_upper_arm_twist", "revolute", names[1], names[2], (0, s * 0.15, 0),
                  (0, 1, 0), (-2.5, 2.5)),
            joint(f"{side}_elbow", "revolute", names[2], names[3], (0, s * 0.15, 0), (0, 0, 1),
                  (-2.6, 2.6)),
            joint(f"{side}_wrist_pitch", "revolute", names[3], names[4], (0.3, 0, 0), (0, 0, 1),
                  (-1.6, 1.6)),
            joint(f"{side}_wrist_flex", "revolute", names[4], names[5], (0, 0, 0), (0, 1, 0),
                  (-1.6, 1.6)),
            joint(f"{side}_tool_mount", "fixed", names[5], names[6], (0.1, 0, 0)),
        ]
    return ('<?xml version="1.0"?>\n'
            '<!-- A two-armed robot on a turning torso, with a head that pans and tilts '
            '(docs/trees.md,\n     "Robot trees"): 15 revolute joints in a tree, two hands and '
            'a camera as tools.\n     Written by examples/python/make_robot_two_arms.py. -->\n'
            '<robot name="two_arms">\n' + ''.join(f'  <link name="{l}"/>\n' for l in links) +
            ''.join(joints) + '</robot>\n')


def smooth(t):
    return t * t * (3 - 2 * t)


def scenario():
    starts = {1: (0.4, 0.57, 1.05), -1: (0.4, -0.57, 1.05)}  # the hands at the zero pose
    paths = {}
    for s in (1, -1):
        center, radius = (0.5, s * 0.3, 1.1), 0.12

        def circle(a):
            return (center[0], center[1] + s * radius * math.cos(a),
                    center[2] + radius * math.sin(a))

        first = circle(0.0)
        points = [tuple(starts[s][i] + smooth(f / 30) * (first[i] - starts[s][i])
                        for i in range(3)) for f in range(1, 31)]
        points += [circle(s * 4 * math.pi * f / 150) for f in range(1, 151)]
        paths[s] = [[round(x, 6) for x in p] for p in points]
    ahead = (1.1, 0.0, 1.34)  # straight ahead of the camera at the zero pose
    look = [[round(ahead[i] + smooth(min(1.0, f / 30)) * (p[i] - ahead[i]), 6) for i in range(3)]
            for f, p in enumerate(paths[1], start=1)]
    return {"format": "flexkin-tree", "name": "two-armed robot",
            "robot": {"urdf": "robot_two_arms.urdf", "base_link": "base_link"},
            "targets": [{"link": "l_tool", "path": paths[1]},
                        {"link": "r_tool", "path": paths[-1]},
                        {"link": "camera", "axis": [1, 0, 0], "look_at": look}]}


def main():
    directory = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "examples")
    (directory / "robot_two_arms.urdf").write_text(urdf())
    (directory / "tree_robot_two_arms.json").write_text(json.dumps(scenario(), indent=1) + "\n")


if __name__ == "__main__":
    main()
