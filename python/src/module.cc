// The extension module flexkin._flexkin, re-exported by python/flexkin/__init__.py
// (docs/python.md).
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "convert.h"
#include "flexkin/vocabulary.h"

namespace flexkin::python {
namespace {

// For flexkin/__init__.py's check of keyword arguments: (message, expected) for `keyword`, which
// is none of `keywords`, with the nearest of them suggested as the library suggests names
// (EditDistance at most 2):
//   unknown keyword "substep"; did you mean "substeps"? Expected one of "points", ... or "overall"
py::tuple UnknownKeyword(const std::string& keyword, const std::vector<std::string>& keywords) {
  const std::string expected = QuotedList(keywords);
  std::string message = "unknown keyword \"" + keyword + "\"";
  size_t best = 3;
  std::string nearest;
  for (const std::string& candidate : keywords) {
    const size_t distance = EditDistance(keyword, candidate);
    if (distance < best) {
      best = distance;
      nearest = candidate;
    }
  }
  message += nearest.empty() ? "; expected " : "; did you mean \"" + nearest + "\"? Expected ";
  message += (keywords.size() == 1 ? "" : "one of ") + expected;
  return py::make_tuple(message, expected);
}

}  // namespace
}  // namespace flexkin::python

PYBIND11_MODULE(_flexkin, m) {
  m.doc() =
      "flexkin: natural, length-preserving motion of chains of rigid links and fixed-base "
      "hyper-redundant arms (the C++ library's bindings; import flexkin).";
  // The version of the library and of `flexkin --version` (the project's version, CMake).
  m.attr("__version__") = FLEXKIN_VERSION;
  flexkin::python::BindErrors(m);
  flexkin::python::BindOptions(m);
  flexkin::python::BindChains(m);
  flexkin::python::BindRun(m);
  flexkin::python::BindRobot(m);
  flexkin::python::BindArms(m);
  flexkin::python::BindStrands(m);
  flexkin::python::BindGroom(m);
#ifdef FLEXKIN_PYTHON_URDF
  flexkin::python::BindUrdf(m);
#endif
#ifdef FLEXKIN_PYTHON_RENDER
  flexkin::python::BindRender(m);
#endif
  m.def("_unknown_keyword", &flexkin::python::UnknownKeyword, pybind11::arg("keyword"),
        pybind11::arg("keywords"),
        "(message, expected) for a keyword argument that is none of `keywords`, with the "
        "nearest one suggested (flexkin/__init__.py).");
}
