// The extension module flexkin._flexkin, re-exported by python/flexkin/__init__.py
// (docs/python.md).
#include "convert.h"

PYBIND11_MODULE(_flexkin, m) {
  m.doc() =
      "flexkin: natural, length-preserving motion of chains of rigid links and fixed-base "
      "hyper-redundant arms (the C++ library's bindings; import flexkin).";
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
}
