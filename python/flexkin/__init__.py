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

from . import _flexkin
from ._flexkin import (
    AccuracyReport,
    ArmModel,
    ArmOptions,
    ArmStepReport,
    BodyPose,
    Chain,
    InputError,
    Metrics,
    ObjectiveWeights,
    OverallOptions,
    OverallReport,
    OverallRunReport,
    Result,
    RobotResult,
    RobotScenario,
    RunOptions,
    Scenario,
    StrandBatch,
    StrandOptions,
    StrandRunReport,
    arc,
    arm_step,
    chain_points,
    estimate_output,
    follow_the_leader_step,
    forward_kinematics,
    groom_summary,
    helix,
    joint_angles_from_points,
    joint_groups,
    joint_groups_report,
    joint_quaternions,
    line,
    load_robot_scenario,
    load_scenario,
    move_leader,
    overall_objective,
    overall_step,
    parabola,
    read_result,
    resample_path,
    run_strands,
    split_pull,
    tool_pose,
    tractrix_step,
    validate_scenario,
    within_limits,
    write_result,
)

# The render options and the URDF functions exist where their components are built (the
# default CMake build); elsewhere their names raise RuntimeError saying so.
_RENDER_CLASSES = ("AnimationOptions", "FigureOptions", "GltfOptions", "PlotOptions",
                   "ViewerOptions")


def _not_built(name, what, option):
    def missing(*args, **kwargs):
        raise RuntimeError(f"flexkin.{name} is not built in this module: {what} ({option})")
    missing.__name__ = name
    missing.__doc__ = f"flexkin.{name}: not built: {what} ({option})."
    return missing


_RENDER_WHAT = ("the render, viewer and glTF components are built with the apps or the tests",
                "configure with FLEXKIN_BUILD_APPS=ON")
_URDF_WHAT = ("the URDF component needs Debian's liburdfdom-dev",
              "install it and configure again")
for _name in _RENDER_CLASSES + ("render", "gltf_joint_positions"):
    globals()[_name] = getattr(_flexkin, _name, None) or _not_built(_name, *_RENDER_WHAT)
for _name in ("arm_from_urdf", "urdf_from_arm"):
    globals()[_name] = getattr(_flexkin, _name, None) or _not_built(_name, *_URDF_WHAT)

# The C++ classes are defined in flexkin._flexkin; they are documented and pickled as flexkin's.
_CLASSES = ("AccuracyReport", "ArmModel", "ArmOptions", "ArmStepReport", "BodyPose", "Chain",
            "Metrics", "ObjectiveWeights", "OverallOptions", "OverallReport", "OverallRunReport",
            "Result", "RobotResult", "RobotScenario", "RunOptions", "Scenario", "StrandBatch",
            "StrandOptions", "StrandRunReport") + _RENDER_CLASSES
for _name in _CLASSES:
    if isinstance(globals()[_name], type):
        globals()[_name].__module__ = __name__
del _name


class _ProgressBar:
    """progress=True: a tqdm bar where tqdm is installed, else a line on stderr rewritten."""

    def __init__(self, what):
        self._what = what
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
            print(f"\rflexkin: {self._what} {done} of {total}", end=end, file=sys.stderr,
                  flush=True)
        self._done = done


def _progress(progress, what):
    if progress is True:
        return _ProgressBar(what)
    return None if progress is False else progress


_PROGRESS_DOC = """
progress=True shows a tqdm progress bar (a line on stderr where tqdm is not installed)."""


def run(points, leader_steps, *, progress=None, **options):
    return _flexkin.run(points, leader_steps, progress=_progress(progress, "leader step"),
                        **options)


def run_scenario(scenario, *, progress=None):
    return _flexkin.run_scenario(scenario, progress=_progress(progress, "leader step"))


def run_robot(scenario, *, progress=None, **options):
    return _flexkin.run_robot(scenario, progress=_progress(progress, "target"), **options)


def track_path(model, path, *, progress=None, **options):
    return _flexkin.track_path(model, path, progress=_progress(progress, "target"), **options)


def run_groom(scenario, output, *, progress=None, **options):
    return _flexkin.run_groom(scenario, output, progress=_progress(progress, "frame"), **options)


for _function in (run, run_scenario, run_robot, track_path, run_groom):
    _function.__doc__ = getattr(_flexkin, _function.__name__).__doc__ + _PROGRESS_DOC
del _function

__all__ = [
    "AccuracyReport", "AnimationOptions", "ArmModel", "ArmOptions", "ArmStepReport", "BodyPose",
    "Chain",
    "FigureOptions", "GltfOptions", "InputError", "Metrics", "ObjectiveWeights",
    "OverallOptions", "OverallReport", "OverallRunReport", "PlotOptions", "Result",
    "RobotResult", "RobotScenario", "RunOptions", "Scenario", "StrandBatch", "StrandOptions",
    "StrandRunReport", "ViewerOptions",
    "arc", "arm_from_urdf", "arm_step", "chain_points", "estimate_output", "follow_the_leader_step",
    "forward_kinematics", "gltf_joint_positions", "groom_summary", "helix", "joint_angles_from_points", "joint_groups",
    "joint_groups_report", "joint_quaternions", "line",
    "load_robot_scenario", "load_scenario", "move_leader", "overall_objective", "overall_step",
    "parabola", "read_result", "render", "resample_path", "run", "run_robot", "run_scenario",
    "run_groom", "run_strands",
    "split_pull", "tool_pose", "track_path", "tractrix_step", "urdf_from_arm", "validate_scenario",
    "within_limits", "write_result",
]
