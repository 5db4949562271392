"""flexkin: natural, length-preserving motion of chains of rigid links and fixed-base arms.

A numpy-native binding of the flexkin C++ library (docs/python.md). Points are float64 arrays
of shape (n+1, dim), dim 2 or 3, row 0 the leading end; every array argument accepts any
array-like that numpy converts to float64. Bad input raises flexkin.InputError (a ValueError)
naming the argument or field; files that cannot be read raise OSError.

    import flexkin
    pts = flexkin.parabola(a=1.0, links=20, link_length=0.25)        # (21, 2)
    steps = flexkin.split_pull(pts[0], [0.5, 0.5], 5)                 # (5, 2) leader steps
    res = flexkin.run(pts, steps, method="tractrix", substeps=8)
    res.frames, res.steps, res.metrics.l2_total, res.brief_report()
    res = flexkin.run_scenario("examples/fig10_planar_curve.json")   # as `flexkin run`
    traj = flexkin.run_robot("examples/robot_planar_8link.json")      # as `flexkin robot`
"""

from ._flexkin import (
    AccuracyReport,
    ArmModel,
    ArmOptions,
    ArmStepReport,
    Chain,
    InputError,
    Metrics,
    ObjectiveWeights,
    OverallOptions,
    OverallReport,
    OverallRunReport,
    Result,
    RobotResult,
    RunOptions,
    Scenario,
    arc,
    arm_step,
    follow_the_leader_step,
    forward_kinematics,
    helix,
    joint_angles_from_points,
    line,
    load_scenario,
    move_leader,
    overall_step,
    parabola,
    resample_path,
    run,
    run_robot,
    run_scenario,
    split_pull,
    track_path,
    tractrix_step,
)

# The C++ classes are defined in flexkin._flexkin; they are documented and pickled as flexkin's.
for _name in ("AccuracyReport", "ArmModel", "ArmOptions", "ArmStepReport", "Chain", "Metrics", "ObjectiveWeights", "OverallOptions",
              "OverallReport", "OverallRunReport", "Result", "RobotResult", "RunOptions",
              "Scenario"):
    globals()[_name].__module__ = __name__
del _name

__all__ = [
    "AccuracyReport", "ArmModel", "ArmOptions", "ArmStepReport", "Chain", "InputError", "Metrics", "ObjectiveWeights", "OverallOptions",
    "OverallReport", "OverallRunReport", "Result", "RobotResult", "RunOptions", "Scenario",
    "arc", "follow_the_leader_step", "helix", "line", "load_scenario", "move_leader",
    "overall_step", "parabola", "resample_path", "run", "run_robot", "run_scenario",
    "split_pull", "tractrix_step", "arm_step", "forward_kinematics", "joint_angles_from_points",
    "track_path",
]
