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

import ast as _ast
import inspect as _inspect
import os as _os
import re as _re

from . import _flexkin
from ._flexkin import (
    AccuracyReport,
    ArmModel,
    ArmOptions,
    ArmStepReport,
    BodyPose,
    Chain,
    ContactReport,
    InputError,
    Metrics,
    ObjectiveWeights,
    OverallOptions,
    OverallReport,
    OverallRunReport,
    PathReport,
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
    move_tree,
    path_deviation,
    overall_objective,
    overall_step,
    parabola,
    reach_tree,
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

# The version of the C++ library and of `flexkin --version` (the CMake project's version).
__version__ = _flexkin.__version__

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
            "ContactReport", "Metrics", "ObjectiveWeights", "OverallOptions", "OverallReport", "OverallRunReport",
            "PathReport", "Result", "RobotResult", "RobotScenario", "RunOptions", "Scenario", "StrandBatch",
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


# Signatures and argument errors. pybind11's functions are builtins: inspect.signature cannot
# read them, and a call it cannot match raises a TypeError that prints every argument's value
# (whole arrays) after the supported signature. So each public function is a thin Python
# function and each class's __init__ a thin method around the C++ one, with an
# inspect.Signature built from the signature line pybind11 itself writes at the top of the doc
# string (from the py::arg names, types and defaults of the C++ definition, so the parameters
# are declared once, in C++, and cannot drift from a copy here). A call goes straight to C++;
# only when pybind11 refuses it does the wrapper look at what was passed, to raise
# KeywordError for an unknown keyword (the nearest one suggested, as the library suggests
# names) or a TypeError without the values. Written by hand instead, the wrappers would repeat
# every default; a __text_signature__ needs doc strings pybind11 does not write.

class KeywordError(InputError, TypeError):
    """An unknown keyword argument: a TypeError, as Python raises for one, and a
    flexkin.InputError whose field is the keyword, value the keyword quoted and expected the
    valid keywords. str(e): 'flexkin.run(): unknown keyword "substep"; did you mean
    "substeps"? Expected one of "points", ... or "progress"'."""


KeywordError.__module__ = __name__

_EMPTY = _inspect.Parameter.empty
_SIMPLE_TYPES = {"float": float, "int": int, "bool": bool, "str": str, "None": None,
                 "object": object}


class _Default:
    """A default value that is not a Python literal, shown as pybind11 wrote it."""

    def __init__(self, text):
        self._text = text

    def __repr__(self):
        return self._text


def _scan(text):
    """(index, char, depth) of each character of `text` outside quotes, with the bracket depth
    after it."""
    depth, quote = 0, None
    for i, char in enumerate(text):
        if quote:
            quote = None if char == quote else quote
            continue
        if char in "'\"":
            quote = char
            continue
        if char in "([{":
            depth += 1
        elif char in ")]}":
            depth -= 1
        yield i, char, depth


def _split(text):
    """The comma-separated parts of `text` outside brackets and quotes."""
    parts, start = [], 0
    for i, char, depth in _scan(text):
        if char == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    parts.append(text[start:].strip())
    return [part for part in parts if part]


def _annotation(text):
    return _SIMPLE_TYPES.get(text, text) if text else _EMPTY


def _default(text):
    if text is None:
        return _EMPTY
    try:
        return _ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return _Default(text)


def _parse_signature(doc, name):
    """The inspect.Signature of pybind11's signature line `name(...) -> type` (the first line
    of `doc`); None where there is none (an overloaded function)."""
    line = (doc or "").split("\n", 1)[0]
    if not line.startswith(name + "("):
        return None
    close = next((i for i, char, depth in _scan(line) if char in ")]}" and depth == 0), None)
    if close is None:
        return None
    returns = line[close + 1:].strip()
    returns = _annotation(returns[2:].strip()) if returns.startswith("->") else _EMPTY
    parameters, kind = [], _inspect.Parameter.POSITIONAL_OR_KEYWORD
    for part in _split(line[len(name) + 1:close]):
        if part == "*":
            kind = _inspect.Parameter.KEYWORD_ONLY
            continue
        if part == "/":
            parameters = [p.replace(kind=_inspect.Parameter.POSITIONAL_ONLY) for p in parameters]
            continue
        match = _re.match(r"^(\*{0,2})(\w+)(?::\s*(.*?))?(?:\s+=\s+(.*))?$", part)
        if match is None:
            return None
        stars, pname, annotation, default = match.groups()
        if stars == "*":
            kind = _inspect.Parameter.KEYWORD_ONLY
            parameters.append(_inspect.Parameter(pname, _inspect.Parameter.VAR_POSITIONAL))
        elif stars == "**":
            parameters.append(_inspect.Parameter(pname, _inspect.Parameter.VAR_KEYWORD))
        else:
            parameters.append(_inspect.Parameter(pname, kind, default=_default(default),
                                                 annotation=_annotation(annotation)))
    return _inspect.Signature(parameters, return_annotation=returns)


def _keywords(signature):
    """The names a call may pass by keyword; None if it takes any (**kwargs)."""
    kinds = (_inspect.Parameter.POSITIONAL_OR_KEYWORD, _inspect.Parameter.KEYWORD_ONLY)
    if any(p.kind == p.VAR_KEYWORD for p in signature.parameters.values()):
        return None
    return [p.name for p in signature.parameters.values() if p.kind in kinds]


def _keyword_error(where, keyword, keywords):
    message, expected = _flexkin._unknown_keyword(keyword, keywords)
    error = KeywordError(f"{where}: {message}")
    error.field, error.message, error.value, error.expected = (keyword, message, f'"{keyword}"',
                                                               expected)
    return error


def _check_keywords(where, keywords, kwargs):
    if keywords is not None:
        for keyword in kwargs:
            if keyword not in keywords:
                raise _keyword_error(where, keyword, keywords)


def _describe(value):
    """A short description of an argument for a message: its type, and its value if short."""
    shape = getattr(value, "shape", None)
    if shape is not None and hasattr(value, "dtype"):
        return f"{type(value).__name__} of shape {tuple(shape)} and dtype {value.dtype}"
    text = repr(value)
    kind = type(value).__name__
    return f"{text} ({kind})" if len(text) <= 60 else f"a {kind}"


def _refused(where, signature, keywords, args, kwargs):
    """The error for a call that pybind11 refused: KeywordError for an unknown keyword, else a
    TypeError that names the arguments and their types (never their whole values)."""
    _check_keywords(where, keywords, kwargs)
    try:
        bound = signature.bind(*args, **kwargs)
    except TypeError as error:
        return TypeError(f"{where}: {error}")
    given = ", ".join(f"{name}={_describe(value)}" for name, value in bound.arguments.items())
    return TypeError(f"{where}: an argument has a type that does not fit: {given or 'none'}; "
                     f"expected {where[:-2].rsplit('.', 1)[-1]}{signature}")


def _is_refusal(error):
    text = str(error)
    return ("incompatible function arguments" in text.split("\n", 1)[0]
            or "incompatible constructor arguments" in text.split("\n", 1)[0])


def _function(name, prepare=None, extra_doc="", missing_file=None):
    """The module's function `name`: the C++ one with its signature, its keyword arguments
    prepared by `prepare(kwargs)` (progress=True), pybind11's refusal turned into a clear
    error, and a FileNotFoundError explained by `missing_file(name, signature, args, kwargs,
    error)` where that returns an error."""
    builtin = getattr(_flexkin, name)
    signature = _parse_signature(builtin.__doc__, name)
    if signature is None:
        raise ImportError(f"flexkin: no signature line in the doc of {name}")
    where = f"flexkin.{name}()"
    keywords = _keywords(signature)

    def function(*args, **kwargs):
        try:
            return builtin(*args, **(prepare(kwargs) if prepare is not None else kwargs))
        except TypeError as error:
            if not _is_refusal(error):
                raise
            refused = _refused(where, signature, keywords, args, kwargs)
        except FileNotFoundError as error:
            refused = missing_file and missing_file(name, signature, args, kwargs, error)
            if refused is None:
                raise
        raise refused

    if prepare is not None and "progress" in signature.parameters:
        progress = signature.parameters["progress"].replace(
            annotation="Union[bool, Callable[[int, int], object], None]")
        signature = signature.replace(parameters=[
            progress if p.name == "progress" else p for p in signature.parameters.values()])
    function.__name__ = function.__qualname__ = name
    function.__module__ = __name__
    function.__doc__ = builtin.__doc__ + extra_doc
    function.__signature__ = signature
    function.__wrapped__ = builtin
    return function


def _progress_of(what):
    def prepare(kwargs):
        if "progress" not in kwargs:
            return kwargs
        return dict(kwargs, progress=_progress(kwargs["progress"], what))
    return prepare


def _urdf_hint(name, signature, args, kwargs, error):
    """A FileNotFoundError naming /urdf for a dict's relative "urdf" file looked up in the
    working directory (no directory=); None for any other error."""
    try:
        bound = signature.bind(*args, **kwargs)
    except TypeError:
        return None
    scenario = bound.arguments.get("scenario")
    if not isinstance(scenario, dict) or bound.arguments.get("directory") is not None:
        return None
    urdf = scenario.get("urdf")
    if not isinstance(urdf, (str, _os.PathLike)):
        return None
    urdf = _os.fspath(urdf)
    if _os.path.isabs(urdf):
        return None
    tried = _os.path.abspath(urdf)
    if _os.path.exists(tried):
        return None
    return FileNotFoundError(
        error.errno,
        f"flexkin.{name}(): /urdf: \"{urdf}\" is a relative path and no directory= was given, "
        f"so it was looked up in the working directory; pass directory= (the folder it is "
        f"relative to) or an absolute path. No such file", tried)


def _constructor(cls):
    """Gives `cls` (a class of the extension) its signature and clear argument errors."""
    original = cls.__dict__.get("__init__")
    doc = getattr(original, "__doc__", None) or ""
    signature = _parse_signature(doc, "__init__")
    if signature is None:
        # No constructor (pybind11 refuses the call): objects of the class come from the
        # module's functions (a Result from run, a Metrics from a Result, ...).
        cls.__signature__ = _inspect.Signature()
        return
    where = f"flexkin.{cls.__name__}()"
    parameters = list(signature.parameters.values())[1:]        # without self
    names = [p.name for p in parameters]
    if names == ["kwargs"] and cls.__name__ == "ObjectiveWeights":
        # The keywords are the objective terms, which the library checks (with any given, the
        # terms not given are 0).
        parameters = [_inspect.Parameter("terms", _inspect.Parameter.VAR_KEYWORD,
                                         annotation=float)]
    elif names == ["kwargs"]:
        # Options(**fields): every field by keyword, its default that of the C++ struct.
        defaults = cls()
        fields = [n for n, v in vars(cls).items() if isinstance(v, property) and v.fset]
        parameters = [
            _inspect.Parameter(n, _inspect.Parameter.KEYWORD_ONLY, default=getattr(defaults, n),
                               annotation=type(getattr(defaults, n)))
            for n in fields]
    signature = signature.replace(parameters=parameters, return_annotation=_EMPTY)
    keywords = _keywords(signature)

    def __init__(self, *args, **kwargs):
        _check_keywords(where, keywords, kwargs)
        try:
            original(self, *args, **kwargs)
        except TypeError as error:
            if not _is_refusal(error):
                raise
            refused = _refused(where, signature, keywords, args, kwargs)
        else:
            return
        raise refused

    __init__.__qualname__ = f"{cls.__name__}.__init__"
    __init__.__doc__ = original.__doc__
    __init__.__signature__ = signature.replace(parameters=[
        _inspect.Parameter("self", _inspect.Parameter.POSITIONAL_ONLY)] + parameters)
    cls.__init__ = __init__
    cls.__signature__ = signature


__all__ = [
    "AccuracyReport", "AnimationOptions", "ArmModel", "ArmOptions", "ArmStepReport", "BodyPose",
    "Chain", "ContactReport",
    "FigureOptions", "GltfOptions", "InputError", "KeywordError", "Metrics", "ObjectiveWeights",
    "OverallOptions", "OverallReport", "OverallRunReport", "PathReport", "PlotOptions", "Result",
    "RobotResult", "RobotScenario", "RunOptions", "Scenario", "StrandBatch", "StrandOptions",
    "StrandRunReport", "ViewerOptions",
    "arc", "arm_from_urdf", "arm_step", "chain_points", "estimate_output", "follow_the_leader_step",
    "forward_kinematics", "gltf_joint_positions", "groom_summary", "helix", "joint_angles_from_points", "joint_groups",
    "joint_groups_report", "joint_quaternions", "line",
    "load_robot_scenario", "load_scenario", "move_leader", "move_tree", "overall_objective", "overall_step",
    "parabola", "path_deviation", "reach_tree", "read_result", "render", "resample_path", "run", "run_robot", "run_scenario",
    "run_groom", "run_strands",
    "split_pull", "tool_pose", "track_path", "tractrix_step", "urdf_from_arm", "validate_scenario",
    "within_limits", "write_result",
]


# A relative "urdf" of a robot scenario dict is looked up in the working directory unless
# directory= says where (docs/robot-format.md): these say so when the file is not found.
_ROBOT_READERS = ("run_robot", "load_robot_scenario", "validate_scenario")
# progress=True: what the bar counts.
_PROGRESS = {"run": "leader step", "run_scenario": "leader step", "run_robot": "target",
             "track_path": "target", "run_groom": "frame"}


def _wrap_extension():
    """Every public function and class of the extension with its signature and clear argument
    errors (the functions replaced by their wrappers, the classes given an __init__)."""
    for name in __all__:
        obj = getattr(_flexkin, name, None)
        if isinstance(obj, type):
            if not issubclass(obj, BaseException):
                _constructor(obj)
        elif obj is not None:
            globals()[name] = _function(
                name, _progress_of(_PROGRESS[name]) if name in _PROGRESS else None,
                _PROGRESS_DOC if name in _PROGRESS else "",
                _urdf_hint if name in _ROBOT_READERS else None)
    for error in (InputError, KeywordError):
        error.__signature__ = _inspect.Signature(
            [_inspect.Parameter("args", _inspect.Parameter.VAR_POSITIONAL)])


_wrap_extension()
