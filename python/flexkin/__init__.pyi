# Type stubs of the flexkin module (docs/python.md). Arrays are numpy float64 unless noted.
import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Float64Array = npt.NDArray[np.float64]
PathLike = Union[str, "os.PathLike[str]"]
Progress = Union[None, bool, Callable[[int, int], Any]]
OverallArg = Union[None, "OverallOptions", "ObjectiveWeights", Dict[str, float]]

class InputError(ValueError):
    field: str
    message: str
    value: str
    expected: str

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
    overall: OverallOptions
    def __init__(self, *, method: str = "tractrix", substeps: int = 1, record_every: int = 1,
                 tolerance: float = 0.0, max_substeps: int = 65536, link_angles: bool = True,
                 overall: OverallArg = None) -> None: ...
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
    weights: ObjectiveWeights
    method: str
    lengths: Float64Array
    num_steps: int
    substeps: int
    seconds: float
    scenario: str
    dim: int
    num_links: int
    def brief_report(self) -> str: ...
    def full_report(self) -> str: ...
    def write(self, path: PathLike) -> None: ...

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
    points: Float64Array  # (T, n+1, dim)
    ee_error: Float64Array
    base_error: Float64Array
    iterations: npt.NDArray[np.int64]
    sweeps: npt.NDArray[np.int64]
    passes: npt.NDArray[np.int64]
    legs: npt.NDArray[np.int64]
    restarts: npt.NDArray[np.int64]
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
    max_iterations: int
    total_sweeps: int
    total_passes: int
    seconds: float
    def brief_report(self) -> str: ...

def line(*, start: ArrayLike = ..., direction: ArrayLike = ..., links: int = 10,
         link_length: float = 0.1) -> Float64Array: ...
def parabola(*, a: float = 1.0, links: int = 20, link_length: float = 0.25,
             side: int = 1) -> Float64Array: ...
def arc(*, radius: float = 1.0, center: ArrayLike = ..., start_angle: float = 0.0,
        clockwise: bool = False, links: int = 10, link_length: float = 0.1) -> Float64Array: ...
def helix(*, radius: float = 1.0, pitch: float = 1.0, center: ArrayLike = ...,
          start_angle: float = 0.0, clockwise: bool = False, links: int = 20,
          link_length: float = 1.5) -> Float64Array: ...
def split_pull(start: ArrayLike, pull: ArrayLike, steps: int) -> Float64Array: ...
def resample_path(start: ArrayLike, path: ArrayLike, max_step: float) -> Float64Array: ...
def tractrix_step(head_old: ArrayLike, head_new: ArrayLike, tail: ArrayLike,
                  length: float) -> Float64Array: ...
def follow_the_leader_step(head_old: ArrayLike, head_new: ArrayLike, tail: ArrayLike,
                           length: float) -> Float64Array: ...
def move_leader(points: PointsArg, target: ArrayLike, *, method: str = "tractrix",
                substeps: int = 1) -> Float64Array: ...
def overall_step(points: PointsArg, head: ArrayLike, *,
                 options: OverallArg = None) -> Tuple[Float64Array, OverallReport]: ...
def run(points: PointsArg, leader_steps: ArrayLike, *, method: str = "tractrix",
        substeps: int = 1, record_every: int = 1, tolerance: float = 0.0,
        max_substeps: int = 65536, link_angles: bool = True, overall: OverallArg = None,
        progress: Progress = None) -> Result: ...
def load_scenario(scenario: Union[PathLike, Dict[str, Any]]) -> Scenario: ...
def run_scenario(scenario: Union[PathLike, Dict[str, Any], Scenario], *,
                 progress: Progress = None) -> Result: ...
def run_robot(scenario: Union[PathLike, Dict[str, Any]], *, directory: Optional[PathLike] = None,
              method: Optional[str] = None) -> RobotResult: ...
def read_result(path: PathLike) -> Result: ...
def write_result(result: Result, path: PathLike) -> None: ...
def validate_scenario(scenario: Union[PathLike, Dict[str, Any]]) -> List[Dict[str, str]]: ...
def estimate_output(num_links: int, dim: int, num_steps: int, *, record_every: int = 1,
                    link_angles: bool = True) -> Dict[str, Union[int, bool]]: ...
def render(result: Result, out_dir: PathLike,
           formats: Union[str, Sequence[str]] = ("svg", "png", "plots"), *,
           stem: str = "result", every: int = 0, width: Optional[int] = None,
           height: Optional[int] = None, azimuth: Optional[float] = None,
           elevation: Optional[float] = None, fps: Optional[int] = None,
           max_frames: Optional[int] = None, title: str = "",
           ffmpeg: str = "ffmpeg") -> List[str]: ...

class ArmModel:
    def __init__(self, link_lengths: ArrayLike, *, dim: int = 2, base: Optional[ArrayLike] = None,
                 base_direction: Optional[ArrayLike] = None,
                 joint_min: Optional[ArrayLike] = None, joint_max: Optional[ArrayLike] = None,
                 max_bend: Optional[ArrayLike] = None, joint_axes: Optional[ArrayLike] = None,
                 link_directions: Optional[ArrayLike] = None,
                 initial_angles: Optional[ArrayLike] = None,
                 initial_azimuths: Optional[ArrayLike] = None) -> None: ...
    @staticmethod
    def straight(dim: int, links: int, link_length: float) -> "ArmModel": ...
    dim: int
    link_lengths: Float64Array
    base: Float64Array
    base_direction: Float64Array
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
    def __init__(self, *, method: str = "newton", tolerance: float = 1e-10,
                 max_iterations: int = 100, max_fixed_point_iterations: int = 100000,
                 restarts: int = 8, substeps: int = 1, edge_margin: float = 1e-9) -> None: ...

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
    def brief_report(self) -> str: ...

def forward_kinematics(model: ArmModel, angles: ArrayLike,
                       azimuths: Optional[ArrayLike] = None) -> Float64Array: ...
def joint_angles_from_points(model: ArmModel, points: ArrayLike
                             ) -> Tuple[Float64Array, Optional[Float64Array]]: ...
def arm_step(model: ArmModel, target: ArrayLike, *, state: Optional[ArmStepReport] = None,
             options: Optional[ArmOptions] = None) -> ArmStepReport: ...
def track_path(model: ArmModel, path: ArrayLike, *,
               options: Optional[ArmOptions] = None) -> RobotResult: ...
