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
    estimate_output,
    read_result,
    validate_scenario,
    write_result,
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
    run_robot,
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

from . import _flexkin


class _ProgressBar:
    """progress=True: a tqdm bar where tqdm is installed, else a line on stderr rewritten."""

    def __init__(self):
        self._bar = None
        self._done = 0

    def __call__(self, done, total):
        if self._bar is None:
            try:
                from tqdm import tqdm
                self._bar = tqdm(total=total, unit="step")
            except ImportError:
                self._bar = False
        if self._bar:
            self._bar.update(done - self._done)
            if done >= total:
                self._bar.close()
        else:
            import sys
            end = "\n" if done >= total else ""
            print(f"\rflexkin: leader step {done} of {total}", end=end, file=sys.stderr,
                  flush=True)
        self._done = done


def _progress(progress):
    return _ProgressBar() if progress is True else (None if progress is False else progress)


def run(points, leader_steps, *, progress=None, **options):
    return _flexkin.run(points, leader_steps, progress=_progress(progress), **options)


def run_scenario(scenario, *, progress=None):
    return _flexkin.run_scenario(scenario, progress=_progress(progress))


run.__doc__ = _flexkin.run.__doc__ + """
progress=True shows a tqdm progress bar (a line on stderr where tqdm is not installed)."""
run_scenario.__doc__ = _flexkin.run_scenario.__doc__ + """
progress=True shows a tqdm progress bar (a line on stderr where tqdm is not installed)."""

if hasattr(_flexkin, "render"):
    render = _flexkin.render
else:
    def render(result, out_dir, formats=("svg", "png", "plots"), **options):
        """flexkin.render: not built (the render, viewer and glTF components are built with
        the apps or the tests: FLEXKIN_BUILD_APPS or FLEXKIN_BUILD_TESTS)."""
        raise RuntimeError("flexkin.render is not built in this module: configure with "
                           "FLEXKIN_BUILD_APPS=ON (the render, viewer and glTF components)")

__all__ = [
    "AccuracyReport", "ArmModel", "ArmOptions", "ArmStepReport", "Chain", "InputError", "Metrics", "ObjectiveWeights", "OverallOptions",
    "OverallReport", "OverallRunReport", "Result", "RobotResult", "RunOptions", "Scenario",
    "arc", "follow_the_leader_step", "helix", "line", "load_scenario", "move_leader",
    "overall_step", "parabola", "resample_path", "run", "run_robot", "run_scenario",
    "split_pull", "tractrix_step", "arm_step", "forward_kinematics", "joint_angles_from_points",
    "track_path", "read_result", "write_result", "validate_scenario", "estimate_output",
    "render",
]
