# Type stubs of the flexkin module (docs/python.md). Arrays are numpy float64 unless noted.
import os
from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Float64Array = npt.NDArray[np.float64]
PathLike = Union[str, "os.PathLike[str]"]
Progress = Union[None, bool, Callable[[int, int], Any]]
OverallArg = Union[None, "OverallOptions", "ObjectiveWeights", Dict[str, float]]
ArmOptionsArg = Union[None, "ArmOptions", Dict[str, Any]]

# Every class below also compares field by field (==), pickles, copies and prints as
# Name(field=value, ...) or a one-line summary.

class InputError(ValueError):
    field: str
    message: str
    value: str
    expected: str

class KeywordError(InputError, TypeError): ...

__version__: str

class ObjectiveWeights:
    squared: float
    squared_weighted: float
    rotation: float
    joint_angle: float
    l2: float
    l2_weighted: float
    def __init__(self, **terms: float) -> None: ...
    def validate(self) -> None: ...
    def as_dict(self) -> Dict[str, float]: ...

class OverallOptions:
    weights: ObjectiveWeights
    constraint_tolerance: float
    optimality_tolerance: float
    max_iterations: int
    def __init__(self, *, weights: Union[None, ObjectiveWeights, Dict[str, float]] = None,
                 constraint_tolerance: float = 1e-12, optimality_tolerance: float = 1e-12,
                 max_iterations: int = 50) -> None: ...
    def validate(self) -> None: ...

class RunOptions:
    method: str
    substeps: int
    record_every: int
    tolerance: float
    max_substeps: int
    link_angles: bool
    link_radius: float
    colliders: List[Dict[str, Any]]
    overall: OverallOptions
    def __init__(self, *, method: str = "tractrix", substeps: int = 1, record_every: int = 1,
                 tolerance: float = 0.0, max_substeps: int = 65536, link_angles: bool = True,
                 overall: OverallArg = None, colliders: Optional[Sequence[Dict[str, Any]]] = None,
                 link_radius: float = 0.0) -> None: ...
    def validate(self) -> None: ...

class Metrics:
    @property
    def l2_per_step(self) -> Float64Array: ...
    @property
    def l2_weighted_per_step(self) -> Float64Array: ...
    @property
    def l2_total(self) -> float: ...
    @property
    def l2_weighted_total(self) -> float: ...
    @property
    def max_relative_length_error(self) -> float: ...
    @property
    def path_length(self) -> Float64Array: ...

class AccuracyReport:
    enabled: bool
    tolerance: float
    max_substeps: int
    substeps: int
    order: int
    estimated_error: float
    met: bool

class OverallRunReport:
    solves: int
    failures: int
    iterations: int
    max_iterations: int
    constraint_violation: float
    optimality: float
    first_failure: str

class ContactReport:
    num_colliders: int
    contact_link_steps: int
    least_clearance: float

class PathReport:
    enabled: bool
    clearance: Float64Array  # (m,)
    tip_error: Float64Array  # (m,)
    deviation: Float64Array  # (m,)
    least_clearance: float
    least_clearance_step: int
    max_tip_error: float
    max_deviation: float

class StrandRunReport:
    max_length_error: float
    seconds: float
    engine: str
    threads: int
    energy: List[float]  # dynamic strands: per recorded frame (frame 0 NaN)
    failures: int
    contact_substeps: int

class OverallReport:
    status: str
    converged: bool
    iterations: int
    objective: float
    constraint_violation: float
    optimality: float
    start: str
    moving_points: int
    def brief_report(self) -> str: ...

class Chain:
    def __init__(self, points: ArrayLike, *, link_length: Optional[float] = None,
                 lengths: Optional[ArrayLike] = None) -> None: ...
    @property
    def points(self) -> Float64Array: ...
    @property
    def lengths(self) -> Float64Array: ...
    @property
    def dim(self) -> int: ...
    @property
    def num_links(self) -> int: ...
    def max_relative_length_error(self) -> float: ...
    def move_leader(self, target: ArrayLike, *, method: str = "tractrix",
                    substeps: int = 1) -> None: ...
    def overall_step(self, head: ArrayLike, *, options: OverallArg = None) -> OverallReport: ...

PointsArg = Union[ArrayLike, Chain]

class Result:
    frames: Float64Array  # (F, n+1, dim)
    steps: npt.NDArray[np.int64]  # (F,)
    link_angles: Optional[Float64Array]  # (F, n)
    metrics: Metrics
    accuracy: AccuracyReport
    overall: OverallRunReport
    contacts: ContactReport
    path: PathReport
    weights: ObjectiveWeights
    method: str
    lengths: Float64Array
    num_steps: int
    substeps: int
    seconds: float
    scenario: str
    dim: int
    num_links: int
    dynamics: Optional[Dict[str, Any]]  # a dynamic chain's: projection, ..., energy; else None
    def brief_report(self) -> str: ...
    def full_report(self) -> str: ...
    def write(self, path: PathLike) -> None: ...
    def write_csv(self, path: PathLike) -> None: ...

class Scenario:
    name: str
    description: str
    chain: Chain
    leader_steps: Float64Array
    options: RunOptions
    def summary(self) -> str: ...

class RobotResult:
    link_lengths: Float64Array
    base: Float64Array
    path: Float64Array  # (T, dim)
    initial_angles: Float64Array
    initial_azimuths: Optional[Float64Array]
    initial_points: Float64Array
    angles: Float64Array  # (T, n)
    azimuths: Optional[Float64Array]  # (T, n), spherical joints
    points: Float64Array  # (T, g, dim): one point per distinct position (joint_groups)
    ee_error: Float64Array
    base_error: Float64Array
    pointing_error: Float64Array
    velocity_ratio: Float64Array
    iterations: npt.NDArray[np.int64]
    sweeps: npt.NDArray[np.int64]
    passes: npt.NDArray[np.int64]
    legs: npt.NDArray[np.int64]
    restarts: npt.NDArray[np.int64]
    velocity_legs: npt.NDArray[np.int64]
    converged: npt.NDArray[np.bool_]
    reached: npt.NDArray[np.bool_]
    stretched: npt.NDArray[np.bool_]
    limited: npt.NDArray[np.bool_]
    joint_space: npt.NDArray[np.bool_]
    scenario: str
    method: str
    joint: str
    dim: int
    num_steps: int
    unreached: int
    max_ee_error: float
    max_base_error: float
    max_pointing_error: float
    max_iterations: int
    total_sweeps: int
    total_passes: int
    total_velocity_legs: int
    seconds: float
    def brief_report(self) -> str: ...

# The curve generators take a scenario file's "curve" fields (docs/scenario-format.md).
# clockwise= and side=1/-1 are the deprecated forms of turn= and side="+x"/"-x".
def line(*, start: Optional[ArrayLike] = None, direction: Optional[ArrayLike] = None,
         links: int = 10, link_length: float = 0.1) -> Float64Array: ...
def parabola(*, a: float = 1.0, links: int = 20, link_length: float = 0.25,
             side: Literal["+x", "-x"] = "+x") -> Float64Array: ...
def arc(*, radius: float = 1.0, center: ArrayLike = ..., start_angle: float = 0.0,
        turn: Literal["ccw", "cw"] = "ccw", links: int = 10, link_length: float = 0.1,
        clockwise: Optional[bool] = None) -> Float64Array: ...
def helix(*, radius: float = 1.0, pitch: float = 1.0, center: ArrayLike = ...,
          start_angle: float = 0.0, turn: Literal["ccw", "cw"] = "ccw", links: int = 20,
          link_length: float = 1.5, clockwise: Optional[bool] = None) -> Float64Array: ...
def split_pull(start: ArrayLike, pull: ArrayLike, steps: int) -> Float64Array: ...
def resample_path(start: ArrayLike, path: ArrayLike, max_step: float) -> Float64Array: ...
def tractrix_step(head_old: ArrayLike, head_new: ArrayLike, tail: ArrayLike,
                  length: float) -> Float64Array: ...
def follow_the_leader_step(head_old: ArrayLike, head_new: ArrayLike, tail: ArrayLike,
                           length: float) -> Float64Array: ...
def move_leader(points: PointsArg, target: ArrayLike, *, method: str = "tractrix",
                substeps: int = 1) -> Float64Array: ...
def move_tree(points: ArrayLike, parents: Sequence[int], path: ArrayLike, *, driven: int = 0,
              method: str = "tractrix", substeps: int = 1) -> Float64Array: ...
def reach_tree(points: ArrayLike, parents: Sequence[int], targets: Sequence[int],
               paths: ArrayLike, *, fixed: Sequence[int] = ..., weights: Optional[ArrayLike] = None,
               method: str = "tractrix", branch_rule: str = "centroid", tolerance: float = 1e-10,
               max_passes: int = 1000,
               overall: Union[None, "ObjectiveWeights", Dict[str, float]] = None,
               looks: Sequence[bool] = ..., finish: bool = True
               ) -> Tuple[Float64Array, Dict[str, Any]]: ...
def overall_step(points: PointsArg, head: ArrayLike, *,
                 options: OverallArg = None) -> Tuple[Float64Array, OverallReport]: ...
def run(points: PointsArg, leader_steps: ArrayLike, *, method: str = "tractrix",
        substeps: int = 1, record_every: int = 1, tolerance: float = 0.0,
        max_substeps: int = 65536, link_angles: bool = True, overall: OverallArg = None,
        colliders: Optional[Sequence[Dict[str, Any]]] = None, link_radius: float = 0.0,
        progress: Progress = None) -> Result: ...
def load_scenario(scenario: Union[PathLike, Dict[str, Any]]) -> Scenario: ...
def run_scenario(scenario: Union[PathLike, Dict[str, Any], Scenario], *,
                 progress: Progress = None, output: Optional[PathLike] = None,
                 csv: Optional[PathLike] = None) -> Union[Result, "RobotResult",
                                                           "StrandRunReport", Dict[str, Any]]: ...
def run_robot(scenario: Union[PathLike, Dict[str, Any], "RobotScenario"], *,
              directory: Optional[PathLike] = None, method: Optional[str] = None,
              progress: Progress = None, output: Optional[PathLike] = None,
              csv: Optional[PathLike] = None) -> RobotResult: ...
def load_robot_scenario(scenario: Union[PathLike, Dict[str, Any]], *,
                        directory: Optional[PathLike] = None) -> "RobotScenario": ...
def path_deviation(points: PointsArg, leader_steps: ArrayLike,
                   result: Result) -> Dict[str, Float64Array]: ...
def read_result(path: PathLike) -> Result: ...
def write_result(result: Result, path: PathLike) -> None: ...
def validate_scenario(scenario: Union[PathLike, Dict[str, Any]], *,
                      directory: Optional[PathLike] = None) -> List[Dict[str, str]]: ...
def overall_objective(weights: Union["ObjectiveWeights", Dict[str, float]], lengths: ArrayLike,
                      old_points: ArrayLike, new_points: ArrayLike, *, gradient: bool = False,
                      hessian: bool = False
                      ) -> Union[float, Tuple[float, Float64Array],
                                 Tuple[float, Float64Array, Float64Array]]: ...
def estimate_output(num_links: int, dim: int, num_steps: int, *, record_every: int = 1,
                    link_angles: bool = True) -> Dict[str, Union[int, bool]]: ...
class FigureOptions:
    every_k: int
    width: int
    height: int
    azimuth: float
    elevation: float
    title: str
    show_leader_path: bool
    show_legend: bool
    def __init__(self, *, every_k: int = 0, width: int = 960, height: int = 0,
                 azimuth: float = -60.0, elevation: float = 30.0, title: str = "",
                 show_leader_path: bool = True, show_legend: bool = True) -> None: ...
    def validate(self) -> None: ...

class PlotOptions:
    width: int
    height: int
    title: str
    def __init__(self, *, width: int = 800, height: int = 500, title: str = "") -> None: ...
    def validate(self) -> None: ...

class AnimationOptions:
    width: int
    height: int
    fps: int
    every_k: int
    max_frames: int
    min_seconds: float
    end_pause: float
    azimuth: float
    elevation: float
    title: str
    ffmpeg: str
    crf: int
    def __init__(self, *, width: int = 640, height: int = 0, fps: int = 30, every_k: int = 0,
                 max_frames: int = 300, min_seconds: float = 3.0, end_pause: float = 1.0,
                 azimuth: float = -60.0, elevation: float = 30.0, title: str = "",
                 ffmpeg: str = "ffmpeg", crf: int = 20) -> None: ...
    def validate(self) -> None: ...

class ViewerOptions:
    title: str
    playback_seconds: float
    autoplay: bool
    loop: bool
    show_leader_path: bool
    trail_points: List[int]
    azimuth: float
    elevation: float
    perspective: bool
    digits: int
    def __init__(self, *, title: str = "", playback_seconds: float = 10.0, autoplay: bool = True,
                 loop: bool = True, show_leader_path: bool = True,
                 trail_points: Sequence[int] = (), azimuth: float = -60.0,
                 elevation: float = 25.0, perspective: bool = False, digits: int = 9) -> None: ...
    def validate(self) -> None: ...

class GltfOptions:
    steps_per_second: float
    include_mesh: bool
    tube_radius: float
    tube_sides: int
    scale: float
    up_axis: str  # "auto", "y" or "z"
    def __init__(self, *, steps_per_second: float = 30.0, include_mesh: bool = True,
                 tube_radius: float = 0.0, tube_sides: int = 12, scale: float = 1.0,
                 up_axis: str = "auto") -> None: ...
    def validate(self) -> None: ...

def gltf_joint_positions(path: PathLike) -> Tuple[Float64Array, Float64Array]: ...
def render(result: Union[Result, RobotResult, PathLike], out_dir: PathLike,
           formats: Union[str, Sequence[str], None] = None, *,
           stem: Optional[str] = None, every: Optional[int] = None, width: Optional[int] = None,
           height: Optional[int] = None, azimuth: Optional[float] = None,
           elevation: Optional[float] = None, fps: Optional[int] = None,
           max_frames: Optional[int] = None, max_strands: Optional[int] = None,
           title: Optional[str] = None,
           ffmpeg: Optional[str] = None,
           figure: Union[None, FigureOptions, Dict[str, Any]] = None,
           plot: Union[None, PlotOptions, Dict[str, Any]] = None,
           animation: Union[None, AnimationOptions, Dict[str, Any]] = None,
           viewer: Union[None, ViewerOptions, Dict[str, Any]] = None,
           gltf: Union[None, GltfOptions, Dict[str, Any]] = None) -> List[str]: ...

class ArmModel:
    def __init__(self, link_lengths: ArrayLike, *, dim: int = 2, base: Optional[ArrayLike] = None,
                 base_direction: Optional[ArrayLike] = None,
                 joint_min: Optional[ArrayLike] = None, joint_max: Optional[ArrayLike] = None,
                 max_bend: Optional[ArrayLike] = None, joint_axes: Optional[ArrayLike] = None,
                 link_directions: Optional[ArrayLike] = None,
                 initial_angles: Optional[ArrayLike] = None,
                 initial_azimuths: Optional[ArrayLike] = None,
                 joint_types: Optional[List[str]] = None,
                 max_velocity: Optional[ArrayLike] = None,
                 tip_rotation: Optional[ArrayLike] = None,
                 joint_names: Optional[List[str]] = None) -> None: ...
    @staticmethod
    def straight(dim: int, links: int, link_length: float) -> "ArmModel": ...
    def validate(self) -> None: ...
    dim: int
    link_lengths: Float64Array
    base: Float64Array
    base_direction: Float64Array
    joint_min: Optional[Float64Array]
    joint_max: Optional[Float64Array]
    max_bend: Optional[Float64Array]
    joint_axes: Optional[Float64Array]  # (n, 3)
    link_directions: Optional[Float64Array]  # (n, 3)
    joint_types: List[str]  # "revolute" / "prismatic" (arms with joint_axes), else []
    max_velocity: Optional[Float64Array]  # (n,)
    tip_rotation: Float64Array  # (4,) w, x, y, z
    joint_names: List[str]
    initial_angles: Float64Array
    initial_azimuths: Optional[Float64Array]
    joint: str
    num_links: int
    reach: float
    has_limits: bool

class ArmOptions:
    method: str
    tolerance: float
    max_iterations: int
    max_fixed_point_iterations: int
    restarts: int
    substeps: int
    edge_margin: float
    time_step: float
    pointing_axis: Float64Array  # (3,), tool frame
    pointing_direction: Optional[Float64Array]  # (3,)
    look_at: Optional[Float64Array]  # (3,)
    pointing_weight: float
    pointing_tolerance: float
    def __init__(self, *, method: str = "newton", tolerance: float = 1e-10,
                 max_iterations: int = 100, max_fixed_point_iterations: int = 100000,
                 restarts: int = 8, substeps: int = 1, edge_margin: float = 1e-9,
                 time_step: float = 0.0, pointing_axis: Optional[ArrayLike] = None,
                 pointing_direction: Optional[ArrayLike] = None,
                 look_at: Optional[ArrayLike] = None, pointing_weight: float = 1.0,
                 pointing_tolerance: float = 1e-9) -> None: ...
    def validate(self) -> None: ...

class ArmStepReport:
    points: Float64Array
    angles: Float64Array
    azimuths: Optional[Float64Array]
    ee_error: float
    base_error: float
    iterations: int
    sweeps: int
    passes: int
    converged: bool
    reached: bool
    stretched: bool
    limited: bool
    joint_space: bool
    legs: int
    restarts: int
    pointing_error: float
    velocity_legs: int
    velocity_ratio: float
    def brief_report(self) -> str: ...

class RobotScenario:
    name: str
    model: ArmModel
    path: Float64Array  # (T, dim)
    options: ArmOptions
    def __init__(self, model: ArmModel, path: ArrayLike, *, options: ArmOptionsArg = None,
                 name: str = "") -> None: ...
    def summary(self) -> str: ...
    def estimate_output(self) -> Dict[str, int]: ...

def forward_kinematics(model: ArmModel, angles: ArrayLike,
                       azimuths: Optional[ArrayLike] = None) -> Float64Array: ...
def joint_quaternions(model: ArmModel, angles: ArrayLike,
                      azimuths: Optional[ArrayLike] = None) -> Float64Array: ...  # (n, 4) w,x,y,z
def within_limits(model: ArmModel, angles: ArrayLike, azimuths: Optional[ArrayLike] = None, *,
                  slack: float = 0.0) -> bool: ...
def joint_angles_from_points(model: ArmModel, points: ArrayLike
                             ) -> Tuple[Float64Array, Optional[Float64Array]]: ...
def arm_step(model: ArmModel, target: ArrayLike, *, state: Optional[ArmStepReport] = None,
             options: ArmOptionsArg = None) -> ArmStepReport: ...
def track_path(model: ArmModel, path: ArrayLike, *, options: ArmOptionsArg = None,
               progress: Progress = None, output: Optional[PathLike] = None,
               csv: Optional[PathLike] = None) -> RobotResult: ...
def joint_groups(model: ArmModel) -> List[List[int]]: ...
def chain_points(model: ArmModel, points: ArrayLike) -> Float64Array: ...  # (g, dim)
def joint_groups_report(model: ArmModel) -> str: ...
def tool_pose(model: ArmModel, angles: ArrayLike
              ) -> Tuple[Float64Array, Float64Array]: ...  # (3,), (3, 3)
def arm_from_urdf(source: PathLike, *, base_link: str = "", tip_link: str = "",
                  tip_offset: Optional[ArrayLike] = None) -> ArmModel: ...
def urdf_from_arm(model: ArmModel, robot_name: str = "flexkin_arm") -> str: ...

# The strand engine (docs/strands.md).
class StrandOptions:
    method: str
    substeps: int
    pinned: int
    threads: int
    def __init__(self, *, method: str = "tractrix", substeps: int = 1, pinned: int = 1,
                 threads: int = 1) -> None: ...
    def validate(self) -> None: ...

class BodyPose:
    rotation: Float64Array  # (3, 3)
    translation: Float64Array  # (3,)
    def __init__(self, rotation: Optional[ArrayLike] = None,
                 translation: Optional[ArrayLike] = None) -> None: ...
    @staticmethod
    def from_quaternion(w: float, x: float, y: float, z: float,
                        translation: Optional[ArrayLike] = None) -> "BodyPose": ...
    @staticmethod
    def planar(angle: float, tx: float = 0.0, ty: float = 0.0) -> "BodyPose": ...
    @staticmethod
    def from_matrix(matrix: ArrayLike) -> "BodyPose": ...
    def matrix(self) -> Float64Array: ...  # (4, 4)

# A pose: BodyPose, a dict of its fields, a (rotation (3, 3) or quaternion (4,), translation)
# pair or a (4, 4) homogeneous transform.
PoseArg = Union[BodyPose, ArrayLike, Tuple[ArrayLike, ArrayLike], Dict[str, Any], None]

class StrandBatch:
    def __init__(self, strands: Sequence[ArrayLike], *, method: str = "tractrix",
                 substeps: int = 1, pinned: int = 1, threads: int = 1, rest: PoseArg = None,
                 options: Union[None, StrandOptions, Dict[str, Any]] = None) -> None: ...
    def step(self, pose: PoseArg = None, *, roots: Optional[ArrayLike] = None) -> None: ...
    def strand(self, i: int) -> Float64Array: ...  # (n_i+1, dim)
    def points(self) -> List[Float64Array]: ...
    def as_array(self) -> Float64Array: ...  # (S, n+1, dim)
    def num_links(self, i: int) -> int: ...
    def __len__(self) -> int: ...
    @property
    def dim(self) -> int: ...
    @property
    def engine(self) -> str: ...
    @property
    def options(self) -> StrandOptions: ...
    @property
    def rest(self) -> BodyPose: ...

def run_strands(strands: Sequence[ArrayLike], poses: ArrayLike, *,
                translations: Optional[ArrayLike] = None, record_every: int = 1,
                method: str = "tractrix", substeps: int = 1, pinned: int = 1, threads: int = 1,
                rest: PoseArg = None) -> Float64Array: ...  # (F', S, n+1, dim)

def run_groom(scenario: Union[PathLike, dict], output: PathLike, *, method: Optional[str] = None,
              projection: Optional[str] = None, substeps: Optional[int] = None, pinned: Optional[int] = None,
              threads: Optional[int] = None, record_every: Optional[int] = None,
              precision: Optional[str] = None,
              progress: Optional[Callable[[int, int], object]] = None) -> StrandRunReport: ...
def groom_summary(scenario: Union[PathLike, dict]) -> str: ...
