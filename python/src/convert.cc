#include "convert.h"

#include <pybind11/eigen.h>

#include <cmath>
#include <cstring>
#include <system_error>
#include <utility>

namespace flexkin::python {
namespace {

// flexkin.InputError, made once per process and never released (it outlives the module object
// only as long as the interpreter does).
PyObject* g_input_error = nullptr;

// Text from C++ (paths may hold bytes that are not UTF-8) as a Python str.
py::str Utf8(const std::string& text) {
  PyObject* s = PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "replace");
  if (s == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(s);
}

std::string ShapeText(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < array.ndim(); ++d) {
    text += (d > 0 ? ", " : "") + std::to_string(array.shape(d));
  }
  return text + (array.ndim() == 1 ? ",)" : ")");
}

std::string ExpectedShape(int ndim, int min_rows, int cols, int size) {
  if (ndim == 1) {
    if (size < 0) return "a 1-D array of at least one value";
    return size > 0 ? std::to_string(size) + " values" : "2 or 3 values (a 2D or 3D point)";
  }
  const std::string columns = cols > 0 ? std::to_string(cols) : "2 or 3";
  return "an (m, " + columns + ") array of points, one per row, m >= " + std::to_string(min_rows);
}

}  // namespace

void ThrowInput(const std::string& field, const std::string& message, const std::string& value,
                const std::string& expected) {
  throw InputError(Problem(field, message, value, expected));
}

py::array_t<double, py::array::c_style> ReadArray(py::handle object, const std::string& name,
                                                  int ndim, int min_rows, int cols, int size,
                                                  bool allow_infinite) {
  const std::string expected = ExpectedShape(ndim, min_rows, cols, size);
  if (object.is_none()) ThrowInput(name, "is None; expected " + expected, "None", expected);
  py::array array;
  if (py::isinstance<py::array>(object)) {
    array = py::reinterpret_borrow<py::array>(object);
  } else {
    try {
      array = py::module_::import("numpy").attr("asarray")(object);
    } catch (py::error_already_set& e) {
      ThrowInput(name,
                 "cannot be read as an array of numbers (" + std::string(e.what()) +
                     "); expected " + expected,
                 "", expected);
    }
  }
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    const std::string dtype = py::str(array.dtype());
    ThrowInput(name,
               "has dtype " + dtype + ", which is not a real number type; expected " + expected +
                   " of float or integer numbers",
               dtype, "float or integer numbers");
  }
  if (array.ndim() != ndim) {
    ThrowInput(name, "has shape " + ShapeText(array) + "; expected " + expected, ShapeText(array),
               expected);
  }
  if (ndim == 2) {
    const py::ssize_t rows = array.shape(0), columns = array.shape(1);
    const bool columns_ok = cols > 0 ? columns == cols : (columns == 2 || columns == 3);
    if (rows < min_rows || !columns_ok) {
      ThrowInput(name, "has shape " + ShapeText(array) + "; expected " + expected, ShapeText(array),
                 expected);
    }
  } else {
    const py::ssize_t n = array.shape(0);
    const bool size_ok = size > 0 ? n == size : size < 0 ? n >= 1 : (n == 2 || n == 3);
    if (!size_ok) {
      ThrowInput(name, "has shape " + ShapeText(array) + "; expected " + expected, ShapeText(array),
                 expected);
    }
  }
  // float64 and C-contiguous already: the same array, no copy.
  auto result = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!result) {
    PyErr_Clear();
    ThrowInput(name, "cannot be converted to float64; expected " + expected, "", expected);
  }
  const double* data = result.data();
  const py::ssize_t count = result.size();
  for (py::ssize_t k = 0; k < count; ++k) {
    if (std::isnan(data[k]) || (!allow_infinite && !std::isfinite(data[k]))) {
      const std::string where = ndim == 2 ? name + "[" + std::to_string(k / result.shape(1)) +
                                                "][" + std::to_string(k % result.shape(1)) + "]"
                                          : name + "[" + std::to_string(k) + "]";
      throw InputError(Problem::Invalid(
          where, Num(data[k]), allow_infinite ? "a number (inf: none)" : "a finite number"));
    }
  }
  return result;
}

Points ReadPoints(py::handle object, const std::string& name, int min_rows, int cols) {
  const auto array = ReadArray(object, name, 2, min_rows, cols);
  Points points(array.shape(0), array.shape(1));
  if (points.size() > 0) {
    std::memcpy(points.data(), array.data(), sizeof(double) * static_cast<size_t>(points.size()));
  }
  return points;
}

Eigen::VectorXd ReadVector(py::handle object, const std::string& name, int size) {
  const auto array = ReadArray(object, name, 1, 1, 0, size);
  Eigen::VectorXd vector(array.shape(0));
  std::memcpy(vector.data(), array.data(), sizeof(double) * static_cast<size_t>(vector.size()));
  return vector;
}

py::array_t<double> ToArray(Points&& points) {
  const py::ssize_t rows = points.rows(), cols = points.cols();
  if (points.size() == 0) return py::array_t<double>({rows, cols});
  auto* owned = new Points(std::move(points));
  py::capsule owner(owned, [](void* p) { delete static_cast<Points*>(p); });
  return py::array_t<double>(
      {rows, cols},
      {static_cast<py::ssize_t>(sizeof(double)) * cols, static_cast<py::ssize_t>(sizeof(double))},
      owned->data(), owner);
}

py::array_t<double> ToArray(const Eigen::VectorXd& vector) {
  py::array_t<double> array(vector.size());
  if (vector.size() > 0) {
    std::memcpy(array.mutable_data(), vector.data(),
                sizeof(double) * static_cast<size_t>(vector.size()));
  }
  return array;
}

double CheckFinite(double value, const std::string& name) {
  if (!std::isfinite(value))
    throw InputError(Problem::Invalid(name, Num(value), "a finite number"));
  return value;
}

double CheckPositive(double value, const std::string& name) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw InputError(Problem::Invalid(name, Num(value), "a finite number > 0"));
  }
  return value;
}

std::string Num(double x) { return FormatNumber(x); }

std::string VectorText(const Eigen::VectorXd& v) {
  if (v.size() > 6) return "<" + std::to_string(v.size()) + " values>";
  std::string text = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) text += (i > 0 ? ", " : "") + Num(v[i]);
  return text + "]";
}

std::string Quoted(const std::string& text) { return py::repr(Utf8(text)); }

void BindErrors(py::module_& m) {
  if (g_input_error == nullptr) {
    g_input_error = PyErr_NewExceptionWithDoc(
        "flexkin.InputError",
        "Bad input: a malformed chain, option, array or scenario (a subclass of ValueError).\n\n"
        "str(e) is the library's message, 'field: message'. Attributes:\n"
        "  field:    where: the argument or member path ('points[3][1]', 'substeps') or a\n"
        "            scenario file's JSON pointer ('/leader/steps'); '' for the input as a whole\n"
        "  message:  what is wrong and what would be valid, without the field\n"
        "  value:    the offending value as text ('nan', '0'); '' where it is not one value\n"
        "  expected: what would be valid ('a finite number > 0'); '' if the message says it",
        PyExc_ValueError, nullptr);
    if (g_input_error == nullptr) throw py::error_already_set();
  }
  m.add_object("InputError", py::handle(g_input_error));
  py::register_exception_translator([](std::exception_ptr pointer) {
    try {
      if (pointer) std::rethrow_exception(pointer);
    } catch (const InputError& e) {
      const Problem& p = e.problem();
      py::object error = py::handle(g_input_error)(Utf8(e.what()));
      error.attr("field") = Utf8(p.field);
      error.attr("message") = Utf8(p.message);
      error.attr("value") = Utf8(p.value);
      error.attr("expected") = Utf8(p.expected);
      PyErr_SetObject(g_input_error, error.ptr());
    } catch (const std::system_error& e) {
      // OSError(errno, text) becomes FileNotFoundError, PermissionError, ... by the errno.
      const int code = e.code().value();
      const bool posix = e.code().category() == std::generic_category() ||
                         e.code().category() == std::system_category();
      py::object error = posix && code != 0 ? py::handle(PyExc_OSError)(code, Utf8(e.what()))
                                            : py::handle(PyExc_OSError)(Utf8(e.what()));
      PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
    }
  });
}

}  // namespace flexkin::python

namespace flexkin::python {

py::tuple StateTuple(const py::tuple& state, size_t size, const char* type) {
  if (state.size() != size) {
    ThrowInput("state",
               std::string("the pickled state of ") + type + " has " +
                   std::to_string(state.size()) + " items; expected " + std::to_string(size),
               std::to_string(state.size()), std::to_string(size));
  }
  return state;
}

Method MethodArg(const std::string& name, const std::string& field) {
  return ParseMethod(name, field);
}

}  // namespace flexkin::python

namespace flexkin::python {

std::string ArrayText(py::handle object) {
  if (object.is_none()) return "None";
  if (!py::isinstance<py::array>(object)) return py::repr(object);
  const auto array = py::reinterpret_borrow<py::array>(object);
  const char kind = array.dtype().kind();
  if (array.ndim() == 1 && array.shape(0) <= 6 && (kind == 'f' || kind == 'i' || kind == 'u')) {
    return VectorText(py::cast<Eigen::VectorXd>(object));
  }
  return "<" + ShapeText(array) + " array>";
}

bool SameObjects(py::handle a, py::handle b) {
  if (a.is_none() || b.is_none()) return a.is_none() && b.is_none();
  const bool a_array = py::isinstance<py::array>(a), b_array = py::isinstance<py::array>(b);
  if (a_array || b_array) {
    if (!a_array || !b_array) return false;
    const auto x = py::reinterpret_borrow<py::array>(a), y = py::reinterpret_borrow<py::array>(b);
    if (!x.dtype().equal(y.dtype())) return false;
    return py::module_::import("numpy").attr("array_equal")(x, y).cast<bool>();
  }
  return a.equal(b);
}

}  // namespace flexkin::python
