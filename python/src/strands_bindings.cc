// The strand engine from Python (flexkin/strands.h, docs/strands.md): flexkin.StrandOptions,
// BodyPose, StrandBatch and run_strands. Steps run with the GIL released; a batch's own mutex
// keeps a step and a read of its points from overlapping when Python threads share it.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "convert.h"
#include "fields.h"
#include "flexkin/strands.h"

namespace flexkin::python {
namespace {

// An InputError whose field starts with `from` ("pose") renamed to start with `to` ("rest",
// "poses[3]").
[[noreturn]] void RethrowRenamed(const InputError& e, const std::string& from,
                                 const std::string& to) {
  Problem p = e.problem();
  if (p.field.compare(0, from.size(), from) == 0) p.field = to + p.field.substr(from.size());
  throw InputError(p);
}

// A rotation argument: (3, 3) values, or a quaternion (w, x, y, z) of 4 values.
Eigen::Matrix3d RotationArg(py::handle object, const std::string& name) {
  py::array array;
  try {
    array = py::module_::import("numpy").attr("asarray")(object);
  } catch (py::error_already_set&) {
    array = py::array();
  }
  if (array && array.ndim() == 1) {
    const Eigen::VectorXd q = ReadVector(object, name, 4);
    try {
      return BodyPose::FromQuaternion(q[0], q[1], q[2], q[3], Eigen::Vector3d::Zero()).rotation;
    } catch (const InputError& e) {
      RethrowRenamed(e, "quaternion", name);
    }
  }
  const auto r = ReadArray(object, name, 2, 3, 3);
  if (r.shape(0) != 3) {
    ThrowInput(name, "has " + std::to_string(r.shape(0)) + " rows; expected a (3, 3) rotation",
               std::to_string(r.shape(0)), "a (3, 3) rotation or a quaternion (w, x, y, z)");
  }
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m(i, j) = r.at(i, j);
  }
  return m;
}

// A translation argument: 3 values, or 2 (z = 0).
Eigen::Vector3d TranslationArg(py::handle object, const std::string& name) {
  const Eigen::VectorXd t = ReadVector(object, name);
  return t.size() == 3 ? Eigen::Vector3d(t) : Eigen::Vector3d(t[0], t[1], 0.0);
}

// A (4, 4) homogeneous transform: rotation the top-left block, translation the last column, last
// row (0, 0, 0, 1).
BodyPose MatrixPose(py::handle object, const std::string& name) {
  const auto a = ReadArray(object, name, 2, 4, 4);
  if (a.shape(0) != 4) {
    ThrowInput(name, "has " + std::to_string(a.shape(0)) + " rows; expected a (4, 4) transform",
               std::to_string(a.shape(0)), "a (4, 4) homogeneous transform");
  }
  if (a.at(3, 0) != 0.0 || a.at(3, 1) != 0.0 || a.at(3, 2) != 0.0 || a.at(3, 3) != 1.0) {
    ThrowInput(name, "has a last row that is not (0, 0, 0, 1); expected a homogeneous transform",
               "", "(0, 0, 0, 1)");
  }
  BodyPose pose;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) pose.rotation(i, j) = a.at(i, j);
    pose.translation[i] = a.at(i, 3);
  }
  return pose;
}

// A pose argument: a BodyPose, a dict of its fields, a (rotation, translation) pair (rotation
// (3, 3) or a quaternion (4,)) or a (4, 4) homogeneous transform; None is the identity.
BodyPose PoseArg(py::handle object, const std::string& name) {
  if (object.is_none()) return BodyPose();
  if (py::isinstance<BodyPose>(object)) return py::cast<BodyPose>(object);
  if (py::isinstance<py::dict>(object)) {
    BodyPose pose;
    Fields<BodyPose>::Apply(Fields<BodyPose>::Of(), object, name + ".", &pose);
    return pose;
  }
  if ((py::isinstance<py::tuple>(object) || py::isinstance<py::list>(object)) &&
      py::len(object) == 2) {
    const auto pair = py::reinterpret_borrow<py::sequence>(object);
    BodyPose pose;
    pose.rotation = RotationArg(pair[0], name + ".rotation");
    pose.translation = TranslationArg(pair[1], name + ".translation");
    return pose;
  }
  if (py::isinstance<py::str>(object)) {
    ThrowInput(name,
               "is a str; expected a BodyPose, a (4, 4) transform or a (rotation, "
               "translation) pair");
  }
  return MatrixPose(object, name);
}

// The Python object of a batch: the engine and a mutex that keeps a step (GIL released) and a
// read of the points from overlapping.
struct Batch {
  Batch(const std::vector<Points>& strands, const StrandOptions& options, const BodyPose& rest)
      : batch(strands, options, rest), rest(rest) {}
  StrandBatch batch;
  BodyPose rest;
  mutable std::mutex mutex;
};

std::vector<Points> StrandsArg(py::handle object, const std::string& name) {
  if (object.is_none() || py::isinstance<py::str>(object) ||
      !py::isinstance<py::sequence>(object)) {
    const std::string type = py::str(py::type::of(object).attr("__name__"));
    ThrowInput(name, "is a " + type + "; expected a sequence of (n_i+1, dim) arrays of points",
               type, "a sequence of (n_i+1, dim) arrays");
  }
  std::vector<Points> strands;
  const py::ssize_t count = py::len(object);
  strands.reserve(static_cast<size_t>(count));
  for (py::ssize_t i = 0; i < count; ++i) {
    strands.push_back(ReadPoints(object[py::int_(i)], name + "[" + std::to_string(i) + "]", 2));
  }
  return strands;
}

StrandOptions MakeOptions(const std::string& method, int substeps, int pinned, int threads) {
  StrandOptions o;
  o.method = MethodArg(method);
  o.substeps = substeps;
  o.pinned = pinned;
  o.threads = threads;
  ThrowIfAny(o.Validate());
  return o;
}

std::unique_ptr<Batch> MakeBatch(py::handle strands, const StrandOptions& options,
                                 py::handle rest) {
  std::vector<Points> s = StrandsArg(strands, "strands");
  const BodyPose r = PoseArg(rest, "rest");
  try {
    return std::make_unique<Batch>(s, options, r);
  } catch (const InputError& e) {
    RethrowRenamed(e, "pose", "rest");
  }
}

int IndexArg(const Batch& b, int i) {
  const int size = b.batch.size();
  if (i < -size || i >= size) {
    ThrowInput("i", "is out of range; the batch has " + std::to_string(size) + " strands",
               std::to_string(i),
               "an integer from " + std::to_string(-size) + " to " + std::to_string(size - 1));
  }
  return i < 0 ? i + size : i;
}

// Every strand's link count, or InputError naming `name` if they differ.
int EqualLinks(const StrandBatch& batch, const std::string& name) {
  const int n = batch.size() > 0 ? batch.num_links(0) : 0;
  for (int i = 1; i < batch.size(); ++i) {
    if (batch.num_links(i) != n) {
      ThrowInput(name,
                 "have different link counts (strand 0 has " + std::to_string(n) + ", strand " +
                     std::to_string(i) + " has " + std::to_string(batch.num_links(i)) +
                     "); one array needs equal counts (use points() for a list)",
                 "", "strands of equal link counts");
    }
  }
  return n;
}

// The points of every strand into `out` (S * (n+1) * dim doubles), equal link counts `n`.
void CopyAll(const StrandBatch& batch, int n, Points* scratch, double* out) {
  const size_t each = static_cast<size_t>(n + 1) * static_cast<size_t>(batch.dim());
  for (int i = 0; i < batch.size(); ++i) {
    batch.CopyStrand(i, scratch);
    std::memcpy(out + each * static_cast<size_t>(i), scratch->data(), sizeof(double) * each);
  }
}

void Step(Batch& b, py::handle pose, py::handle roots) {
  if (pose.is_none() == roots.is_none()) {
    ThrowInput(roots.is_none() ? "pose" : "roots",
               roots.is_none() ? "is None and so are roots; give one of them"
                               : "given with pose; give one of them");
  }
  if (!roots.is_none()) {
    const auto r = ReadArray(roots, "roots", 2, 1, b.batch.dim() == 0 ? 0 : b.batch.dim());
    if (r.shape(0) != b.batch.size()) {
      ThrowInput("roots",
                 "has " + std::to_string(r.shape(0)) + " rows; expected " +
                     std::to_string(b.batch.size()) + ", one per strand",
                 std::to_string(r.shape(0)), std::to_string(b.batch.size()));
    }
    const Eigen::Map<const Points> map(r.data(), r.shape(0), r.shape(1));
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(b.mutex);
    StepStrands(&b.batch, map);
    return;
  }
  const BodyPose p = PoseArg(pose, "pose");
  py::gil_scoped_release release;
  std::lock_guard<std::mutex> lock(b.mutex);
  StepStrands(&b.batch, p);
}

std::string BatchRepr(const Batch& b) {
  const StrandBatch& s = b.batch;
  int lo = 0, hi = 0;
  for (int i = 0; i < s.size(); ++i) {
    lo = i == 0 ? s.num_links(i) : std::min(lo, s.num_links(i));
    hi = std::max(hi, s.num_links(i));
  }
  const std::string links =
      lo == hi ? std::to_string(lo) : std::to_string(lo) + " to " + std::to_string(hi);
  return "StrandBatch(" + std::to_string(s.size()) + " strands, " + std::to_string(s.dim()) +
         "D, " + links + " links, " + MethodName(s.options().method) + ", pinned " +
         std::to_string(s.options().pinned) + ", engine " + s.engine() + ")";
}

// Poses of run_strands: (F, 4, 4) transforms, or (F, 3, 3) rotations with `translations` (F, 3)
// or (F, 2).
std::vector<BodyPose> PosesArg(py::handle poses, py::handle translations) {
  std::vector<BodyPose> out;
  if (translations.is_none()) {
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
        py::module_::import("numpy").attr("asarray")(poses, "float64"));
    if (!a || a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4) {
      PyErr_Clear();
      ThrowInput("poses",
                 "is not an (F, 4, 4) array of transforms; expected (F, 4, 4), or (F, 3, 3) "
                 "rotations with translations (F, 3)");
    }
    for (py::ssize_t f = 0; f < a.shape(0); ++f) {
      out.push_back(MatrixPose(a[py::int_(f)], "poses[" + std::to_string(f) + "]"));
    }
    return out;
  }
  const auto r = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
      py::module_::import("numpy").attr("asarray")(poses, "float64"));
  if (!r || r.ndim() != 3 || r.shape(1) != 3 || r.shape(2) != 3) {
    PyErr_Clear();
    ThrowInput("poses",
               "is not an (F, 3, 3) array of rotations; expected (F, 3, 3) with "
               "translations (F, 3)");
  }
  const auto t = ReadArray(translations, "translations", 2, 1, 0);
  if (t.shape(0) != r.shape(0)) {
    ThrowInput("translations",
               "has " + std::to_string(t.shape(0)) + " rows; expected " +
                   std::to_string(r.shape(0)) + ", one per pose",
               std::to_string(t.shape(0)), std::to_string(r.shape(0)));
  }
  for (py::ssize_t f = 0; f < r.shape(0); ++f) {
    const std::string name = "poses[" + std::to_string(f) + "]";
    BodyPose pose;
    pose.rotation = RotationArg(r[py::int_(f)], name);
    pose.translation = TranslationArg(t[py::int_(f)], "translations[" + std::to_string(f) + "]");
    out.push_back(pose);
  }
  return out;
}

}  // namespace

void BindStrands(py::module_& m) {
  py::class_<StrandOptions> options(m, "StrandOptions", R"doc(
Options of the strand engine (flexkin::StrandOptions, docs/strands.md).

StrandOptions(method="tractrix", substeps=1, pinned=1, threads=1)
  method: "tractrix" or "ftl" (follow-the-leader, the hair-simulator baseline).
  substeps: sub-steps per frame (>= 1), as move_leader's.
  pinned: points of each strand rigid with the body (>= 1; 1: the root alone).
  threads: threads stepping the strands (0: one per hardware thread); never changes a result.
)doc");
  options.def(py::init(&MakeOptions), py::kw_only(), py::arg("method") = "tractrix",
              py::arg("substeps") = 1, py::arg("pinned") = 1, py::arg("threads") = 1);
  Fields<StrandOptions>(options, "StrandOptions")
      .Validate("substeps")
      .Property(
          "method", [](const StrandOptions& o) { return std::string(MethodName(o.method)); },
          [](StrandOptions& o, py::handle name) {
            o.method = MethodArg(py::cast<std::string>(name));
          },
          "The link rule: 'tractrix' (default) or 'ftl' (follow-the-leader).", true)
      .Member("substeps", &StrandOptions::substeps,
              "Sub-steps per frame, >= 1 (default 1): the leading end of the first free link "
              "moves in this many equal straight pieces.",
              true)
      .Member("pinned", &StrandOptions::pinned,
              "Points of each strand moved rigidly with the body, >= 1 (default 1: the root "
              "only); a strand with no more points is rigid as a whole.",
              true)
      .Member("threads", &StrandOptions::threads,
              "Threads stepping the strands, 0 to 1024 (default 1; 0: one per hardware thread). "
              "Only the speed depends on it.",
              true)
      .Finish();

  py::class_<BodyPose> pose(m, "BodyPose", R"doc(
The pose of the body the strands grow from: x -> rotation @ x + translation (flexkin::BodyPose).
In 2D the top-left (2, 2) block of rotation and the first two components of translation count.

BodyPose(rotation=None, translation=None)
  rotation: (3, 3) rotation matrix or a quaternion (w, x, y, z) (normalized); None: identity.
  translation: 3 values, or 2 (z = 0); None: zero.
BodyPose.from_quaternion(w, x, y, z, translation), BodyPose.planar(angle, tx, ty) and
BodyPose.from_matrix((4, 4) transform) build one; matrix() gives the (4, 4) transform.
Wherever a pose is taken (StrandBatch.step, rest), a dict of the fields, a (rotation,
translation) pair or a (4, 4) homogeneous transform also do. Rotations are checked (orthonormal,
determinant +1, to 1e-9) when the pose is used.
)doc");
  pose.def(py::init([](OptionalArray rotation, OptionalArray translation) {
             BodyPose p;
             if (!rotation.is_none()) p.rotation = RotationArg(rotation, "rotation");
             if (!translation.is_none()) p.translation = TranslationArg(translation, "translation");
             return p;
           }),
           py::arg("rotation") = py::none(), py::arg("translation") = py::none())
      .def_static(
          "from_quaternion",
          [](double w, double x, double y, double z, OptionalArray translation) {
            const Eigen::Vector3d t = translation.is_none()
                                          ? Eigen::Vector3d::Zero()
                                          : TranslationArg(translation, "translation");
            return BodyPose::FromQuaternion(w, x, y, z, t);
          },
          py::arg("w"), py::arg("x"), py::arg("y"), py::arg("z"),
          py::arg("translation") = py::none(),
          "The rotation of the unit quaternion (w, x, y, z) (normalized here; not zero), then "
          "the translation (3 values, or 2; None: zero).")
      .def_static("planar", &BodyPose::Planar, py::arg("angle"), py::arg("tx") = 0.0,
                  py::arg("ty") = 0.0,
                  "A planar pose: rotation by angle (radians) about z, then the translation "
                  "(tx, ty).")
      .def_static(
          "from_matrix", [](ArrayLike matrix) { return MatrixPose(matrix, "matrix"); },
          py::arg("matrix"),
          "From a (4, 4) homogeneous transform: rotation its top-left (3, 3) block, translation "
          "its last column; the last row must be (0, 0, 0, 1).")
      .def(
          "matrix",
          [](const BodyPose& p) {
            Points a = Points::Identity(4, 4);
            a.topLeftCorner(3, 3) = p.rotation;
            a.topRightCorner(3, 1) = p.translation;
            return ToArray(std::move(a));
          },
          "The (4, 4) float64 homogeneous transform.");
  Fields<BodyPose>(pose, "BodyPose")
      .Property(
          "rotation", [](const BodyPose& p) { return ToArray(Points(p.rotation)); },
          [](BodyPose& p, py::handle v) { p.rotation = RotationArg(v, "rotation"); },
          "(3, 3) float64, a copy: the rotation (set from (3, 3) or a quaternion (w, x, y, z)).",
          true)
      .Property(
          "translation", [](const BodyPose& p) { return ToArray(Eigen::VectorXd(p.translation)); },
          [](BodyPose& p, py::handle v) { p.translation = TranslationArg(v, "translation"); },
          "(3,) float64, a copy: the translation (length unit; set from 3 values or 2).", true)
      .Finish();

  py::class_<Batch> batch(m, "StrandBatch", R"doc(
Many strands (hair, fur, grass) stepped together, one call per frame (docs/strands.md).

StrandBatch(strands, *, method="tractrix", substeps=1, pinned=1, threads=1, rest=None,
            options=None)
  strands: a sequence of (n_i+1, dim) array-likes, row 0 the root; every strand a valid chain
           (n_i >= 1, finite, links of positive length), all of one dim (2 or 3).
  method, substeps, pinned, threads: as StrandOptions; options: a StrandOptions or a dict of
           its fields instead of them.
  rest: the body pose the strands are given at (a BodyPose, (rotation, translation) pair or
        (4, 4) transform; None: identity).
Each step moves each strand's first `pinned` points with the body and the rest by the method's
rule; with pinned=1 each strand is exactly move_leader of it to its new root (bit for bit on the
"scalar" engine, within 1e-14 relative on "avx2" and "avx512"). The number of threads never
changes a result. A batch is an engine with state, not a value: it does not pickle or copy.
)doc");
  batch
      .def(py::init([](StrandList strands, const std::string& method, int substeps, int pinned,
                       int threads, PoseLike rest, StrandOptionsLike options) {
             StrandOptions o = MakeOptions(method, substeps, pinned, threads);
             if (!options.is_none()) {
               o = OptionsArg<StrandOptions>(options, "options");
               try {
                 ThrowIfAny(o.Validate());
               } catch (const InputError& e) {
                 RethrowRenamed(e, "", "options.");
               }
             }
             return MakeBatch(strands, o, rest);
           }),
           py::arg("strands"), py::kw_only(), py::arg("method") = "tractrix",
           py::arg("substeps") = 1, py::arg("pinned") = 1, py::arg("threads") = 1,
           py::arg("rest") = py::none(), py::arg("options") = py::none())
      .def(
          "step", [](Batch& b, PoseLike pose, OptionalArray roots) { Step(b, pose, roots); },
          py::arg("pose") = py::none(), py::kw_only(), py::arg("roots") = py::none(),
          "One frame, with the GIL released: give exactly one of pose (the body's new pose: a "
          "BodyPose, (rotation, translation) pair or (4, 4) transform; each strand's pinned "
          "points go to pose(their body coordinates)) and roots ((S, dim): root i moves to "
          "roots[i], the other pinned points translate with it).")
      .def(
          "strand",
          [](const Batch& b, int i) {
            const int k = IndexArg(b, i);
            std::lock_guard<std::mutex> lock(b.mutex);
            return ToArray(b.batch.strand(k));
          },
          py::arg("i"), "Strand i's points now: (n_i+1, dim) float64, a copy (i < 0 from the end).")
      .def(
          "points",
          [](const Batch& b) {
            std::lock_guard<std::mutex> lock(b.mutex);
            py::list out;
            for (int i = 0; i < b.batch.size(); ++i) out.append(ToArray(b.batch.strand(i)));
            return out;
          },
          "Every strand's points now: a list of (n_i+1, dim) float64 arrays.")
      .def(
          "as_array",
          [](const Batch& b) {
            const int n = EqualLinks(b.batch, "strands");
            py::array_t<double> out({b.batch.size(), n + 1, b.batch.dim()});
            std::lock_guard<std::mutex> lock(b.mutex);
            Points scratch;
            CopyAll(b.batch, n, &scratch, out.mutable_data());
            return out;
          },
          "Every strand's points now as one (S, n+1, dim) float64 array; InputError ('strands') "
          "if the strands' link counts differ.")
      .def(
          "num_links", [](const Batch& b, int i) { return b.batch.num_links(IndexArg(b, i)); },
          py::arg("i"), "n_i, strand i's number of links.")
      .def(
          "__len__", [](const Batch& b) { return b.batch.size(); }, "The number of strands.")
      .def_property_readonly(
          "dim", [](const Batch& b) { return b.batch.dim(); }, "2 or 3 (0 for an empty batch).")
      .def_property_readonly(
          "engine", [](const Batch& b) { return std::string(b.batch.engine()); },
          "The engine stepping the batch: 'avx512', 'avx2' or 'scalar' (FLEXKIN_SIMD caps it).")
      .def_property_readonly(
          "options", [](const Batch& b) { return b.batch.options(); },
          "The batch's StrandOptions (a copy).")
      .def_property_readonly(
          "rest", [](const Batch& b) { return b.rest; },
          "The rest BodyPose the strands were given at (a copy).")
      .def("__repr__", &BatchRepr, "A summary: strands, dim, links, method, pinned, engine.")
      .def(
          "__reduce_ex__",
          [](const Batch&, int) -> py::object {
            throw py::type_error(
                "a StrandBatch is an engine with state and cannot be pickled or copied; pickle "
                "its strands (points()) and options and make a new one");
          },
          py::arg("protocol"), "Refuses: a StrandBatch does not pickle or copy.");

  m.def(
      "run_strands",
      [](StrandList strands, ArrayLike poses, OptionalArray translations, int record_every,
         const std::string& method, int substeps, int pinned, int threads, PoseLike rest) {
        const StrandOptions o = MakeOptions(method, substeps, pinned, threads);
        if (record_every < 1) {
          throw InputError(
              Problem::Invalid("record_every", std::to_string(record_every), "an integer >= 1"));
        }
        std::unique_ptr<Batch> b = MakeBatch(strands, o, rest);
        const int n = EqualLinks(b->batch, "strands");
        const std::vector<BodyPose> p = PosesArg(poses, translations);
        const int count = static_cast<int>(p.size());
        std::vector<int> kept = {0};
        for (int f = 1; f <= count; ++f) {
          if (f % record_every == 0 || f == count) kept.push_back(f);
        }
        const int s = b->batch.size(), dim = b->batch.dim();
        py::array_t<double> frames({static_cast<py::ssize_t>(kept.size()),
                                    static_cast<py::ssize_t>(s), static_cast<py::ssize_t>(n + 1),
                                    static_cast<py::ssize_t>(dim)});
        double* out = frames.mutable_data();
        const size_t each = static_cast<size_t>(s) * static_cast<size_t>(n + 1) * dim;
        {
          py::gil_scoped_release release;
          Points scratch;
          CopyAll(b->batch, n, &scratch, out);
          size_t next = 1;
          for (int f = 1; f <= count; ++f) {
            try {
              StepStrands(&b->batch, p[static_cast<size_t>(f - 1)]);
            } catch (const InputError& e) {
              RethrowRenamed(e, "pose", "poses[" + std::to_string(f - 1) + "]");
            }
            if (next < kept.size() && kept[next] == f) {
              CopyAll(b->batch, n, &scratch, out + each * next);
              ++next;
            }
          }
        }
        return frames;
      },
      py::arg("strands"), py::arg("poses"), py::kw_only(), py::arg("translations") = py::none(),
      py::arg("record_every") = 1, py::arg("method") = "tractrix", py::arg("substeps") = 1,
      py::arg("pinned") = 1, py::arg("threads") = 1, py::arg("rest") = py::none(),
      R"doc(
Steps a StrandBatch through a sequence of body poses with the GIL released and returns the
frames: an (F', S, n+1, dim) float64 array, frame 0 the strands as given, then every
record_every-th pose's frame and the last.

run_strands(strands, poses, *, translations=None, record_every=1, method="tractrix",
            substeps=1, pinned=1, threads=1, rest=None)
  strands: S strands of equal link count n, each (n+1, dim) (InputError 'strands' otherwise;
           use StrandBatch for mixed counts).
  poses: (F, 4, 4) homogeneous transforms; or (F, 3, 3) rotations with
  translations: (F, 3) (or (F, 2)).
  method, substeps, pinned, threads, rest: as StrandBatch.
)doc");
}

}  // namespace flexkin::python
