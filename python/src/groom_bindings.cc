// Grooms from Python (flexkin/groom.h, docs/groom-format.md): flexkin.run_groom runs a groom
// scenario (a path or a dict of its JSON form) into a strand file as `flexkin run` does, with
// the GIL released; flexkin.groom_summary describes one. The strand file is read with
// numpy.load (docs/strands.md).
#include <pybind11/stl.h>

#include <functional>
#include <limits>
#include <string>
#include <utility>

#include "convert.h"
#include "fields.h"
#include "flexkin/any_scenario.h"
#include "flexkin/groom.h"
#include "flexkin/strand_file.h"
#include "flexkin/vocabulary.h"
#include "progress.h"

namespace flexkin::python {
namespace {

using GroomSource = ScenarioFile;  // "Union[PathLike, dict]"

// The scenario a path or a dict stands for; problems of a file carry its path.
GroomScenario GroomArg(GroomSource scenario) {
  if (py::isinstance<py::dict>(scenario)) {
    const std::string text = JsonOfDict(scenario, "scenario");
    py::gil_scoped_release release;
    return ParseGroomText(text);
  }
  const std::string path = PathArg(scenario);
  if (path.empty()) {
    ThrowInput("scenario",
               "is a " + std::string(py::str(py::type::of(scenario).attr("__name__"))) +
                   "; expected a path to a groom scenario file or a dict of its JSON form");
  }
  return OnFile(path, [&] { return LoadGroomFile(path); });
}

// An integer override of a groom's option (a Python int or another integer type, not a bool),
// else InputError naming the keyword and the value; its range is StrandOptions::Validate's.
int IntOverride(py::handle value, const char* name) {
  if (!py::isinstance<py::bool_>(value) && PyIndex_Check(value.ptr())) {
    const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!index) throw py::error_already_set();
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    if (overflow == 0 && v >= std::numeric_limits<int>::min() &&
        v <= std::numeric_limits<int>::max()) {
      return static_cast<int>(v);
    }
    throw InputError(
        Problem::Invalid(name, std::string(py::repr(value)), "an integer of magnitude below 2^31"));
  }
  throw InputError(Problem::Invalid(name, std::string(py::repr(value)), "an integer"));
}

StrandRunReport RunGroomTo(GroomSource source, PathLike output, OptionalStr method,
                           OptionalStr projection, OptionalInt substeps, OptionalInt pinned,
                           OptionalInt threads, OptionalInt record_every, OptionalStr precision,
                           ProgressCallback progress) {
  GroomScenario s = GroomArg(source);
  // Checked by the library as `flexkin run`'s options are (ApplyGroomOverrides, flexkin/groom.h).
  GroomOverrides overrides;
  const auto text = [](py::handle value, const char* name) {
    if (!py::isinstance<py::str>(value)) {
      throw InputError(Problem::Invalid(name, std::string(py::repr(value)), "a string"));
    }
    return py::cast<std::string>(value);
  };
  if (!method.is_none()) overrides.method = text(method, "method");
  if (!projection.is_none()) overrides.projection = text(projection, "projection");
  if (!precision.is_none()) overrides.precision = text(precision, "precision");
  if (!substeps.is_none()) overrides.substeps = IntOverride(substeps, "substeps");
  if (!pinned.is_none()) overrides.pinned = IntOverride(pinned, "pinned");
  if (!threads.is_none()) overrides.threads = IntOverride(threads, "threads");
  if (!record_every.is_none()) overrides.record_every = IntOverride(record_every, "record_every");
  ApplyGroomOverrides(overrides, /*command_line=*/false, &s);
  const std::string path = RequiredPath(output, "output", false);
  ProgressHook hook(progress);
  const std::function<void(int64_t, int64_t)> tick = [&hook](int64_t done, int64_t total) {
    hook.Tick(done, total);
  };
  try {
    // The library's one call for every kind (flexkin/any_scenario.h), as `flexkin run` makes it.
    AnyScenario any;
    any.kind = ScenarioKind::kGroom;
    any.groom = std::move(s);
    return OnFile(path, [&] { return RunScenarioToFiles(any, {path, ""}, tick).strands; });
  } catch (const StopRun&) {
    hook.Rethrow();
  }
}

}  // namespace

void BindGroom(py::module_& m) {
  py::class_<StrandRunReport> report(m, "StrandRunReport", R"doc(
What a groom run did (flexkin.run_groom; also in the strand file's groom.json "report").
  max_length_error (largest relative link-length error of the recorded frames), seconds (wall
  time of the stepping), engine ('avx512', 'avx2' or 'scalar'), threads.
)doc");
  Fields<StrandRunReport>(report, "StrandRunReport")
      .Member("max_length_error", &StrandRunReport::max_length_error,
              "Largest |link length - rest length| / rest length over the recorded frames.")
      .Member("seconds", &StrandRunReport::seconds,
              "Wall time of the stepping, writing excluded (seconds).")
      .Member("engine", &StrandRunReport::engine,
              "The strand engine that ran: 'avx512', 'avx2' or 'scalar'.")
      .Member("threads", &StrandRunReport::threads, "Threads that stepped the strands.")
      .Member("energy", &StrandRunReport::energy,
              "Dynamic strands: the strands' energy at each recorded frame (each strand's free "
              "points weighing 1; frame 0 NaN); empty for kinematic strands.")
      .Member("failures", &StrandRunReport::failures,
              "Dynamic strands, overall projection: strand sub-steps whose Newton solve did not "
              "converge (they kept the tractrix projection).")
      .Member("contact_substeps", &StrandRunReport::contact_substeps,
              "Dynamic strands, overall projection: strand sub-steps projected with contacts by "
              "the tractrix projection.")
      .Finish();

  m.def("run_groom", &RunGroomTo, py::arg("scenario"), py::arg("output"), py::kw_only(),
        py::arg("method") = py::none(), py::arg("projection") = py::none(),
        py::arg("substeps") = py::none(), py::arg("pinned") = py::none(),
        py::arg("threads") = py::none(), py::arg("record_every") = py::none(),
        py::arg("precision") = py::none(), py::arg("progress") = py::none(),
        "Runs a groom scenario (a path to a groom file or a dict of its JSON form, "
        "docs/groom-format.md) and writes the strand file `output` (.npz; read it with "
        "numpy.load: points (F, P, dim), offsets, frames, times, body_rotation, "
        "body_translation, link_lengths, groom.json; docs/strands.md), as `flexkin run` does, "
        "bit for bit. The keyword arguments override the scenario's method ('tractrix' or "
        "'ftl'), projection (dynamic strands: 'overall', 'tractrix' or 'dftl'), substeps, "
        "pinned, threads, record_every and precision ('float32' or 'float64'). The file is written "
        "whole or not at all; Ctrl-C or an exception from "
        "progress(done, total) stops the run and leaves no file. Returns a StrandRunReport.");
  m.def(
      "groom_summary", [](GroomSource scenario) { return GroomSummary(GroomArg(scenario)); },
      py::arg("scenario"),
      "One line describing a groom scenario (a path or a dict), as `flexkin validate` prints "
      "it; raises InputError naming the JSON pointer of a problem.");
}

}  // namespace flexkin::python
