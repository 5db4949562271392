#pragma once
// Long computations run with the GIL released. Their progress hook takes it back about every
// 0.1 s to check for Ctrl-C (PyErr_CheckSignals, which acts in the main thread) and to call the
// user's callback(done, total). A Python exception there (KeyboardInterrupt, or one the callback
// raised) is kept and the computation stopped by throwing StopRun through it; once the GIL is
// back, Rethrow raises the kept exception.
#include <pybind11/pybind11.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <utility>

namespace flexkin::python {

namespace py = pybind11;

struct StopRun {};

class ProgressHook {
 public:
  explicit ProgressHook(py::object callback) : callback_(std::move(callback)) {}

  // Sets `*progress` to a function that calls Call (the hook must outlive the computation).
  void Install(std::function<void(int64_t, int64_t)>* progress) {
    *progress = [this](int64_t done, int64_t total) { Call(done, total); };
  }
  // Call, at most about every 0.1 s (and always when done == total).
  void Tick(int64_t done, int64_t total) {
    const auto now = std::chrono::steady_clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    Call(done, total);
  }
  // Needs the GIL; a kept exception is raised (as py::error_already_set).
  [[noreturn]] void Rethrow() {
    PyErr_Restore(type_.release().ptr(), value_.release().ptr(), trace_.release().ptr());
    throw py::error_already_set();
  }
  // Takes the GIL: checks for signals, calls the callback. Throws StopRun on a Python error.
  void Call(int64_t done, int64_t total) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) Stop();
    if (!callback_.is_none()) {
      PyObject* out = PyObject_CallFunction(callback_.ptr(), "LL", static_cast<long long>(done),
                                            static_cast<long long>(total));
      if (out == nullptr) Stop();
      Py_DECREF(out);
    }
  }

 private:
  [[noreturn]] void Stop() {
    PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
    PyErr_Fetch(&type, &value, &trace);
    type_ = py::reinterpret_steal<py::object>(type);
    value_ = py::reinterpret_steal<py::object>(value);
    trace_ = py::reinterpret_steal<py::object>(trace);
    throw StopRun();
  }

  py::object callback_, type_, value_, trace_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace flexkin::python
