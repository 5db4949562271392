#pragma once
// Conversions between Python objects and flexkin's Eigen types, shared by the binding files.
//
// Every array argument goes through ReadArray: any array-like that numpy converts to float64
// (lists, tuples, integer and float arrays of any layout) is accepted; other dtypes (strings,
// objects, complex, bool), wrong shapes, NaN and inf are refused with flexkin::InputError naming
// the argument ("points", "leader_steps[3][1]"), which the module raises as flexkin.InputError.
// A C-contiguous float64 ndarray is read where it lies (no conversion); flexkin's functions take
// Eigen matrices, so its values are then copied once into the Points the call needs.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <string>
#include <system_error>

#include "flexkin/arm.h"
#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/run.h"

namespace flexkin::python {

namespace py = pybind11;

// Argument types of the bound functions: any Python object, taken as it is and checked by the
// binding (ReadArray, PathArg, ...), named in help()'s signatures by what is expected: Typed<Tag>
// shows as Tag::kText ("ArrayLike", "Union[ArmOptions, dict, None]").
inline bool AnyObject(PyObject*) { return true; }
template <typename Tag>
class Typed : public py::object {
 public:
  PYBIND11_OBJECT_DEFAULT(Typed, object, AnyObject)
};

#define FLEXKIN_PYTHON_ARG(Name, Text)    \
  struct Name##Tag {                      \
    static constexpr char kText[] = Text; \
  };                                      \
  using Name = Typed<Name##Tag>;

FLEXKIN_PYTHON_ARG(ArrayLike, "ArrayLike")
FLEXKIN_PYTHON_ARG(PathLike, "PathLike")
FLEXKIN_PYTHON_ARG(ModelObject, "ArmModel")
FLEXKIN_PYTHON_ARG(ResultObject, "Result")
FLEXKIN_PYTHON_ARG(StepState, "Optional[ArmStepReport]")
FLEXKIN_PYTHON_ARG(ScenarioSource, "Union[PathLike, dict, Scenario]")
FLEXKIN_PYTHON_ARG(RobotScenarioSource, "Union[PathLike, dict, RobotScenario]")
FLEXKIN_PYTHON_ARG(UrdfSource, "Union[str, PathLike]")
FLEXKIN_PYTHON_ARG(ArmOptionsLike, "Union[ArmOptions, dict, None]")
FLEXKIN_PYTHON_ARG(OverallLike, "Union[OverallOptions, ObjectiveWeights, dict, None]")
FLEXKIN_PYTHON_ARG(WeightsLike, "Union[ObjectiveWeights, dict]")
FLEXKIN_PYTHON_ARG(CollidersLike, "Optional[Sequence[dict]]")
FLEXKIN_PYTHON_ARG(FormatList, "Union[str, Sequence[str]]")
FLEXKIN_PYTHON_ARG(ProgressCallback, "Optional[Callable[[int, int], object]]")
FLEXKIN_PYTHON_ARG(OptionalInt, "Optional[int]")
FLEXKIN_PYTHON_ARG(OptionalFloat, "Optional[float]")
FLEXKIN_PYTHON_ARG(OptionalStr, "Optional[str]")
FLEXKIN_PYTHON_ARG(OptionalBool, "Optional[bool]")
FLEXKIN_PYTHON_ARG(NameText, "str")
FLEXKIN_PYTHON_ARG(OptionalArray, "Optional[ArrayLike]")
FLEXKIN_PYTHON_ARG(PointsOrChain, "Union[ArrayLike, Chain]")
FLEXKIN_PYTHON_ARG(OptionalWeights, "Union[ObjectiveWeights, dict, None]")
FLEXKIN_PYTHON_ARG(ScenarioFile, "Union[PathLike, dict]")
FLEXKIN_PYTHON_ARG(OptionalPath, "Optional[PathLike]")
FLEXKIN_PYTHON_ARG(FigureLike, "Union[FigureOptions, dict, None]")
FLEXKIN_PYTHON_ARG(PlotLike, "Union[PlotOptions, dict, None]")
FLEXKIN_PYTHON_ARG(AnimationLike, "Union[AnimationOptions, dict, None]")
FLEXKIN_PYTHON_ARG(ViewerLike, "Union[ViewerOptions, dict, None]")
FLEXKIN_PYTHON_ARG(GltfLike, "Union[GltfOptions, dict, None]")
FLEXKIN_PYTHON_ARG(StrandList, "Sequence[ArrayLike]")
FLEXKIN_PYTHON_ARG(IndexSequence, "Sequence[int]")
FLEXKIN_PYTHON_ARG(PoseLike, "Union[BodyPose, ArrayLike, Tuple[ArrayLike, ArrayLike], dict, None]")
FLEXKIN_PYTHON_ARG(StrandOptionsLike, "Union[StrandOptions, dict, None]")
#undef FLEXKIN_PYTHON_ARG

}  // namespace flexkin::python

namespace pybind11::detail {
template <typename Tag>
struct handle_type_name<flexkin::python::Typed<Tag>> {
  static constexpr auto name = const_name(Tag::kText);
};
}  // namespace pybind11::detail

namespace flexkin::python {

// The float64, C-contiguous form of `object`, checked: `ndim` dimensions (1 or 2); with ndim 2,
// at least `min_rows` rows and 2 or 3 columns (`cols` if it is not 0); with ndim 1, `size`
// values if it is > 0 (2 or 3 if it is 0, any number >= 1 if it is < 0). Every value finite
// (or, if `allow_infinite`, not NaN: limits, -inf/inf for none). Throws InputError naming `name`.
py::array_t<double, py::array::c_style> ReadArray(py::handle object, const std::string& name,
                                                  int ndim, int min_rows = 1, int cols = 0,
                                                  int size = 0, bool allow_infinite = false);

// Checked (n, dim) points (see ReadArray) copied into flexkin's Points.
Points ReadPoints(py::handle object, const std::string& name, int min_rows = 1, int cols = 0);
// A checked vector of `size` values (2 or 3 if size is 0).
Eigen::VectorXd ReadVector(py::handle object, const std::string& name, int size = 0);

// A numpy array that owns `points` (moved, not copied): (rows, cols) float64.
py::array_t<double> ToArray(Points&& points);
// A numpy copy of a vector.
py::array_t<double> ToArray(const Eigen::VectorXd& vector);

// A finite number, else InputError naming `name`.
double CheckFinite(double value, const std::string& name);
// A number > 0 and finite, else InputError naming `name`.
double CheckPositive(double value, const std::string& name);

// "1.5", "nan": a number as the library writes it in messages and reprs.
std::string Num(double x);
// "[1, 2.5]": a short vector for a repr (its size alone when it is long).
std::string VectorText(const Eigen::VectorXd& v);
// A Python string's repr ("'tractrix'").
std::string Quoted(const std::string& text);

// Registers flexkin.InputError (a ValueError with field, message, value, expected) and the
// translation of std::system_error to OSError (FileNotFoundError, PermissionError, ... by errno).
void BindErrors(py::module_& m);
// Throws InputError(Problem(field, message, value, expected)), raised as flexkin.InputError.
[[noreturn]] void ThrowInput(const std::string& field, const std::string& message,
                             const std::string& value = "", const std::string& expected = "");

// Option and report classes (options_bindings.cc), chains, curves, link steps (chains_bindings.cc),
// runs and scenarios (run_bindings.cc), fixed-base arms (robot_bindings.cc).
void BindOptions(py::module_& m);
void BindChains(py::module_& m);
void BindRun(py::module_& m);
void BindRobot(py::module_& m);
void BindArms(py::module_& m);
// The strand engine: StrandOptions, BodyPose, StrandBatch, run_strands (strands_bindings.cc).
void BindStrands(py::module_& m);
void BindGroom(py::module_& m);
// TrackPath of a robot scenario's model along its path with the GIL released, as a
// flexkin.RobotResult (robot_bindings.cc): `progress` a callable(done, total) or None; `output`,
// `csv` None or the paths of the trajectory JSON and the joint CSV, written while the steps come
// and renamed into place only when complete.
py::object TrackToResult(const RobotScenario& scenario, py::object progress, py::handle output,
                         py::handle csv);
// The model argument: an ArmModel, else InputError naming "model" (arm_bindings.cc).
const ArmModel& ModelArg(py::handle model);
// Raises InputError for the first problem of ArmOptions::Validate, the pointing members named
// as the Python keywords (pointing.direction -> pointing_direction, pointing.point -> look_at).
void ThrowIfAnyArmOptions(const ArmOptions& options);
// The robot scenario readers' options: URDF arms read where the URDF component is built,
// relative "urdf" files looked up in `directory` (None: the default) (files.cc).
RobotScenarioOptions RobotReaderOptions(py::handle directory);
// A flexkin.Result as the ResultFile the render, viewer and glTF writers take, no copy: it lives
// as long as `object` (run_bindings.cc); InputError for another object.
const ResultFile& ResultFileOfObject(py::handle object);
// flexkin.render (render_bindings.cc; built where the render, viewer and glTF components are).
void BindRender(py::module_& m);
// flexkin.arm_from_urdf, urdf_from_arm (urdf_bindings.cc; built where the URDF component is).
void BindUrdf(py::module_& m);

}  // namespace flexkin::python

namespace flexkin::python {
// The checked state tuple of a pickled object: `size` items, else InputError naming `type`.
py::tuple StateTuple(const py::tuple& state, size_t size, const char* type);
// Method from its name, as in scenario files ("tractrix", "ftl", ...); InputError naming `field`.
Method MethodArg(const std::string& name, const std::string& field = "method");
// ObjectiveWeights or a dict of term weights (options_bindings.cc), every weight finite; throws
// InputError naming "weights" or "weights.<term>".
ObjectiveWeights WeightsArg(py::handle object);
// The overall options from an `overall` argument: None (the defaults), OverallOptions,
// ObjectiveWeights or a dict of term weights (only the terms given count).
OverallOptions OverallArg(py::handle object);
// RunOptions from the keyword arguments of flexkin.run (options_bindings.cc).
RunOptions MakeRunOptions(const std::string& method, int substeps, int record_every,
                          double tolerance, int max_substeps, bool link_angles, OverallLike overall,
                          CollidersLike colliders, double link_radius);
// Colliders from a list of dicts in the form of a scenario's "colliders" (docs/scenario-format.md;
// None: none), read by the scenario reader (InputError naming "/colliders/k/..."); and back.
std::vector<Collider> CollidersArg(py::handle colliders);
py::object CollidersValue(const std::vector<Collider>& colliders);
// A chain from a `Chain` or from points (link lengths the distances between them; MakeChain).
Chain ChainArg(py::handle object, const std::string& name = "points");
}  // namespace flexkin::python

// Paths and files (files.cc).
namespace flexkin::python {
// JSON text of a dict (numpy arrays and scalars as lists and numbers) for the scenario readers;
// InputError naming `name` if it cannot be written.
std::string JsonOfDict(py::handle dict, const std::string& name);
// A path (str or os.PathLike) as a string, or "" if `object` is not one.
std::string PathArg(py::handle object);
// A path argument, else InputError naming `name`; with `optional`, None is "".
std::string RequiredPath(py::handle object, const std::string& name, bool optional = false);
// A std::system_error with `path` in its message (raised as OSError).
[[noreturn]] void RethrowWithPath(const std::system_error& error, const std::string& path);
// An InputError with the file's path before its field, as the command line prints it.
[[noreturn]] void RethrowInFile(const InputError& error, const std::string& path);

// `access()` on the file the user named at `path` (reading or writing it), with the GIL
// released: an InputError gets the path before its field, a std::system_error the path in its
// message. `access` must not touch Python objects.
template <typename Access>
auto OnFile(const std::string& path, Access access) -> decltype(access()) {
  try {
    py::gil_scoped_release release;
    return access();
  } catch (const InputError& e) {
    RethrowInFile(e, path);
  } catch (const std::system_error& e) {
    RethrowWithPath(e, path);
  }
}
}  // namespace flexkin::python
