// Paths, files and JSON for the bindings: path arguments (str or os.PathLike), the file's name in
// its errors, dicts as the scenario readers' JSON text, and the robot readers' options. Kept apart
// from the bindings of runs and robots, which both use them.
#include <pybind11/pybind11.h>

#include <string>
#include <system_error>

#include "convert.h"
#include "flexkin/robot_scenario.h"
#ifdef FLEXKIN_PYTHON_URDF
#include "flexkin/urdf.h"
#endif

namespace flexkin::python {

// JSON text of a dict (numpy arrays and numbers as lists and numbers) for the scenario readers.
std::string JsonOfDict(py::handle dict, const std::string& name) {
  py::module_ json = py::module_::import("json");
  py::object to_list = py::cpp_function([](py::handle o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error(std::string("an object of type ") +
                         std::string(py::str(py::type::of(o).attr("__name__"))) +
                         " cannot be written as JSON");
  });
  try {
    return py::cast<std::string>(json.attr("dumps")(dict, py::arg("default") = to_list));
  } catch (py::error_already_set& e) {
    ThrowInput(name, "cannot be written as JSON: " + std::string(e.what()));
  }
}

// A path (str or os.PathLike) as a string, or "" if `object` is not one.
std::string PathArg(py::handle object) {
  if (py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__")) {
    return py::cast<std::string>(py::module_::import("os").attr("fsdecode")(object));
  }
  return "";
}

std::string RequiredPath(py::handle object, const std::string& name, bool optional) {
  if (optional && object.is_none()) return "";
  const std::string path = PathArg(object);
  if (path.empty()) {
    ThrowInput(name, std::string("is not a path; expected a str or os.PathLike") +
                         (optional ? ", or None" : ""));
  }
  return path;
}

void RethrowWithPath(const std::system_error& error, const std::string& path) {
  const std::string what = error.what();
  if (what.find(path) != std::string::npos) throw error;
  throw std::system_error(error.code(), path + ": " + what);
}

void RethrowInFile(const InputError& error, const std::string& path) {
  Problem p = error.problem();
  p.field = p.field.empty() ? path : path + ": " + p.field;
  throw InputError(p);
}

// The robot scenario readers' options: URDF arms where the URDF component is built.
RobotScenarioOptions RobotReaderOptions(py::handle directory) {
#ifdef FLEXKIN_PYTHON_URDF
  RobotScenarioOptions options = UrdfRobotScenarioOptions();
#else
  RobotScenarioOptions options;
#endif
  options.directory = RequiredPath(directory, "directory", true);
  return options;
}

}  // namespace flexkin::python
