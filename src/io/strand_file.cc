// Strand files (include/flexkin/strand_file.h, docs/strands.md "The strand file"): the streaming
// writer and the frame-by-frame reader of the .npz archive a groom run writes. The ZIP and .npy
// structures are io/npz's.
#include "flexkin/strand_file.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/vocabulary.h"
#include "io/atomic_file.h"
#include "io/colliders_json.h"
#include "io/json_file.h"
#include "io/npz.h"

namespace flexkin {
namespace {

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "strand files are written as little-endian numbers from memory"
#endif

constexpr const char* kFileKind = "a valid strand file";
constexpr uint64_t kMaxGroomJsonBytes = 1u << 20;

// Every problem of a header, each naming "header.<member>".
Problems HeaderProblems(const StrandFileHeader& h) {
  Problems problems;
  auto add = [&](const std::string& field, const std::string& message, const std::string& value,
                 const std::string& expected) {
    problems.emplace_back("header." + field, message, value, expected);
  };
  if (h.dim != 2 && h.dim != 3) {
    add("dim", "value " + std::to_string(h.dim) + " is not valid; expected 2 or 3",
        std::to_string(h.dim), "2 or 3");
  }
  if (h.offsets.size() < 1 || h.offsets.front() != 0) {
    add("offsets", "must start with 0 (S+1 entries for S strands)", "", "[0, ...]");
    return problems;
  }
  for (size_t i = 1; i < h.offsets.size(); ++i) {
    if (h.offsets[i] - h.offsets[i - 1] < 2) {
      add("offsets[" + std::to_string(i) + "]",
          "value " + std::to_string(h.offsets[i]) + " is not valid; expected at least offsets[" +
              std::to_string(i - 1) + "] + 2 (a strand has at least one link)",
          std::to_string(h.offsets[i]), ">= previous + 2");
      return problems;
    }
  }
  const int64_t links = h.num_points() - h.num_strands();
  if (h.link_lengths.size() != links) {
    add("link_lengths",
        "has " + std::to_string(h.link_lengths.size()) + " values; the strands have " +
            std::to_string(links) + " links",
        "", std::to_string(links) + " values");
  } else {
    for (Eigen::Index i = 0; i < h.link_lengths.size(); ++i) {
      const double l = h.link_lengths[i];
      if (!(std::isfinite(l) && l > 0.0)) {
        add("link_lengths[" + std::to_string(i) + "]", "is not a finite number > 0", "",
            "a finite number > 0");
        break;
      }
    }
  }
  if (h.num_frames < 1) {
    add("num_frames", "value " + std::to_string(h.num_frames) + " is not valid; expected >= 1",
        std::to_string(h.num_frames), "an integer >= 1");
  }
  if (!(std::isfinite(h.fps) && h.fps > 0.0)) {
    add("fps", "is not a finite number > 0", "", "a finite number > 0");
  }
  if (h.dim == 2 || h.dim == 3) {
    for (const auto& [key, list] :
         {std::pair{"body_", &h.body_colliders}, std::pair{"world_", &h.world_colliders}}) {
      for (Problem p : CollidersProblems(*list, h.dim)) {
        p.field = "header." + std::string(key) + p.field;
        problems.push_back(std::move(p));
      }
    }
  }
  return problems;
}

nlohmann::json VectorJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::string GroomJson(const StrandFileHeader& h, const StrandRunReport& report) {
  nlohmann::json j;
  j["format"] = "flexkin strands";
  j["version"] = 1;
  j["name"] = h.name;
  j["description"] = h.description;
  j["dim"] = h.dim;
  j["num_strands"] = h.num_strands();
  j["num_points"] = h.num_points();
  j["num_frames"] = h.num_frames;
  j["precision"] = PrecisionName(h.float32);
  j["fps"] = h.fps;
  j["method"] = h.method;
  j["substeps"] = h.substeps;
  j["pinned"] = h.pinned;
  j["record_every"] = h.record_every;
  j["scalp"] = {{"shape", h.scalp.shape},
                {"center", VectorJson(h.scalp.center)},
                {"radii", VectorJson(h.scalp.radii)}};
  const bool colliders = !h.body_colliders.empty() || !h.world_colliders.empty();
  if (colliders) {
    for (const auto& [key, list] : {std::pair{"body_colliders", &h.body_colliders},
                                    std::pair{"world_colliders", &h.world_colliders}}) {
      nlohmann::json array = nlohmann::json::array();
      for (const Collider& c : *list) {
        std::string text;
        AppendColliderJson(c, h.dim, &text);
        array.push_back(nlohmann::json::parse(text));
      }
      j[key] = array;
    }
  }
  if (h.dynamics) {
    const DynamicOptions& d = *h.dynamics;
    const auto vector = [](const Eigen::VectorXd& v) {
      nlohmann::json a = nlohmann::json::array();
      for (Eigen::Index k = 0; k < v.size(); ++k) a.push_back(v[k]);
      return a;
    };
    j["dynamics"] = {{"projection", ProjectionName(d.projection)},
                     {"gravity", vector(d.gravity)},
                     {"damping", d.damping},
                     {"mass", d.masses.size() != 0 ? vector(d.masses)
                              : d.mass_by_length   ? nlohmann::json("by_length")
                                                   : nlohmann::json("uniform")},
                     {"dftl_damping", d.dftl_damping}};
    if (d.wind.size() != 0) j["dynamics"]["wind"] = vector(d.wind);
    if (h.own_masses) j["dynamics"]["own_masses"] = true;
  }
  j["report"] = {{"max_length_error", report.max_length_error},
                 {"seconds", report.seconds},
                 {"engine", report.engine},
                 {"threads", report.threads}};
  if (h.dynamics) {
    nlohmann::json energy = nlohmann::json::array();
    for (double e : report.energy) {
      energy.push_back(std::isfinite(e) ? nlohmann::json(e) : nlohmann::json(nullptr));
    }
    j["report"]["energy"] = energy;
    j["report"]["failures"] = report.failures;
    j["report"]["contact_substeps"] = report.contact_substeps;
  }
  if (colliders) {
    j["report"]["contact_link_steps"] = report.contact_link_steps;
    // +inf (no link came near a collider) has no JSON number: null.
    j["report"]["least_clearance"] = std::isfinite(report.least_clearance)
                                         ? nlohmann::json(report.least_clearance)
                                         : nlohmann::json(nullptr);
  }
  return j.dump(2) + "\n";
}

// Unsigned shape numbers for an .npy header.
uint64_t U(int64_t v) { return static_cast<uint64_t>(v); }

}  // namespace

struct StrandFileWriter::Impl {
  Impl(const std::string& path, const StrandFileHeader& h)
      : header(h),
        file(path),
        zip(&file),
        rotation(file.directory(), Cannot(path)),
        translation(file.directory(), Cannot(path)),
        frames(file.directory(), Cannot(path)),
        times(file.directory(), Cannot(path)) {}
  static std::string Cannot(const std::string& path) { return "cannot write '" + path + "'"; }

  StrandFileHeader header;
  AtomicFile file;
  ZipWriter zip;
  // The per-frame members, kept out of memory until Commit copies them in after the points.
  ScratchFile rotation, translation, frames, times;
  int64_t added = 0, last_frame = -1;
  std::vector<float> row32;  // one frame's points as float32
  Points strand;             // one strand copied from a batch

  void AddInfo(int64_t frame_number, double time, const BodyPose& pose) {
    if (added >= header.num_frames) {
      throw InputError("frames", "more than the header's num_frames (" +
                                     std::to_string(header.num_frames) + ") were added");
    }
    if (frame_number <= last_frame) {
      throw InputError("frames[" + std::to_string(added) + "].frame",
                       "value " + std::to_string(frame_number) +
                           " is not valid; expected a frame number above the previous one (" +
                           std::to_string(last_frame) + ")");
    }
    if (!std::isfinite(time)) {
      throw InputError("frames[" + std::to_string(added) + "].time", "is not a finite number");
    }
    if (!pose.rotation.allFinite() || !pose.translation.allFinite()) {
      throw InputError("frames[" + std::to_string(added) + "].pose", "is not finite");
    }
    // Row-major 3x3 as numpy reads (F, 3, 3).
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r = pose.rotation;
    rotation.Write(r.data(), sizeof(double) * 9);
    translation.Write(pose.translation.data(), sizeof(double) * 3);
    frames.Write(&frame_number, sizeof frame_number);
    times.Write(&time, sizeof time);
    last_frame = frame_number;
  }

  // Writes `count` coordinates of the frame, checking them; `first_row` names the first point.
  void WriteCoordinates(const double* data, int64_t count, int64_t first_row) {
    for (int64_t k = 0; k < count; ++k) {
      if (!std::isfinite(data[k])) {
        const int64_t row = first_row + k / header.dim;
        throw InputError("frames[" + std::to_string(added) + "].points[" + std::to_string(row) +
                             "][" + std::to_string(k % header.dim) + "]",
                         "is not a finite number; nothing was written");
      }
    }
    if (header.float32) {
      row32.resize(static_cast<size_t>(count));
      for (int64_t k = 0; k < count; ++k) row32[k] = static_cast<float>(data[k]);
      zip.Write(row32.data(), sizeof(float) * row32.size());
    } else {
      zip.Write(data, sizeof(double) * static_cast<size_t>(count));
    }
  }
};

StrandFileWriter::StrandFileWriter(const std::string& path, const StrandFileHeader& header) {
  ThrowIfAny(HeaderProblems(header));
  impl_ = std::make_unique<Impl>(path, header);
  ZipWriter& zip = impl_->zip;
  zip.BeginMember("offsets.npy", NpyHeader("<i8", {U(header.offsets.size())}));
  zip.Write(header.offsets.data(), sizeof(int64_t) * header.offsets.size());
  zip.EndMember();
  zip.BeginMember("link_lengths.npy", NpyHeader("<f8", {U(header.link_lengths.size())}));
  zip.Write(header.link_lengths.data(), sizeof(double) * U(header.link_lengths.size()));
  zip.EndMember();
  zip.BeginMember("points.npy",
                  NpyHeader(header.float32 ? "<f4" : "<f8",
                            {U(header.num_frames), U(header.num_points()), U(header.dim)}));
}

StrandFileWriter::~StrandFileWriter() = default;

void StrandFileWriter::Add(const StrandFrame& frame) {
  Impl& w = *impl_;
  const StrandFileHeader& h = w.header;
  if (frame.points.rows() != h.num_points() || frame.points.cols() != h.dim) {
    throw InputError("frames[" + std::to_string(w.added) + "].points",
                     "has " + std::to_string(frame.points.rows()) + " x " +
                         std::to_string(frame.points.cols()) + " values; expected " +
                         std::to_string(h.num_points()) + " x " + std::to_string(h.dim));
  }
  w.AddInfo(frame.frame, frame.time, frame.pose);
  w.WriteCoordinates(frame.points.data(), frame.points.size(), 0);
  ++w.added;
  w.file.Check();
}

void StrandFileWriter::Add(int64_t frame_number, double time, const BodyPose& pose,
                           const StrandBatch& batch) {
  Impl& w = *impl_;
  const StrandFileHeader& h = w.header;
  if (batch.size() != h.num_strands() || (batch.size() > 0 && batch.dim() != h.dim)) {
    throw InputError("batch", "has " + std::to_string(batch.size()) + " strands of dim " +
                                  std::to_string(batch.dim()) + "; the file has " +
                                  std::to_string(h.num_strands()) + " of dim " +
                                  std::to_string(h.dim));
  }
  for (int i = 0; i < batch.size(); ++i) {
    if (batch.num_links(i) + 1 != h.offsets[i + 1] - h.offsets[i]) {
      throw InputError("batch", "strand " + std::to_string(i) + " has " +
                                    std::to_string(batch.num_links(i)) + " links; the file's has " +
                                    std::to_string(h.offsets[i + 1] - h.offsets[i] - 1));
    }
  }
  w.AddInfo(frame_number, time, pose);
  for (int i = 0; i < batch.size(); ++i) {
    batch.CopyStrand(i, &w.strand);
    w.WriteCoordinates(w.strand.data(), w.strand.size(), h.offsets[i]);
  }
  ++w.added;
  w.file.Check();
}

void StrandFileWriter::Commit(const StrandRunReport& report) {
  Impl& w = *impl_;
  const StrandFileHeader& h = w.header;
  if (w.added != h.num_frames) {
    throw InputError("frames", std::to_string(w.added) + " frames were added; the header has " +
                                   std::to_string(h.num_frames) + "; nothing was written");
  }
  w.zip.EndMember();
  const uint64_t f = U(h.num_frames);
  auto copy = [&](ScratchFile* scratch, const std::string& name, const std::string& descr,
                  const std::vector<uint64_t>& shape) {
    w.zip.BeginMember(name, NpyHeader(descr, shape));
    scratch->CopyTo([&](const char* data, size_t size) { w.zip.Write(data, size); });
    w.zip.EndMember();
  };
  copy(&w.frames, "frames.npy", "<i8", {f});
  copy(&w.times, "times.npy", "<f8", {f});
  copy(&w.rotation, "body_rotation.npy", "<f8", {f, 3, 3});
  copy(&w.translation, "body_translation.npy", "<f8", {f, 3});
  w.zip.AddMember("groom.json", GroomJson(h, report));
  w.zip.Finish();
  w.file.Commit();
}

struct StrandFileReader::Impl {
  explicit Impl(const std::string& path) : zip(path) {}
  ZipReader zip;
  StrandFileHeader header;
  StrandRunReport report;
  std::vector<StrandFrame> info;
  std::unique_ptr<ZipReader::Member> points;
  int64_t next = 0;
  std::vector<float> row32;
};

namespace {

// Reads a whole small member of `descr` with `shape` into `out` (count values of T).
template <typename T>
void ReadMember(ZipReader* zip, const std::string& name, const char* descr,
                const std::vector<uint64_t>& shape, std::vector<T>* out) {
  ZipReader::Member member(zip, name);
  const NpyArray a = ReadNpyHeader(&member, name, descr);
  ExpectNpyShape(a, name, shape, kFileKind);
  out->resize(a.count);
  member.Read(out->data(), sizeof(T) * a.count);
  member.Finish();
}

// groom.json's value at `key`, of the type asked, or InputError naming "groom.json/key".
template <typename T>
T Get(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end()) throw InputError(std::string("groom.json/") + key, "is missing");
  try {
    return it->get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(std::string("groom.json/") + key,
                     "value " + it->dump() + " has the wrong type; not " + kFileKind);
  }
}

Eigen::Vector3d GetVector(const nlohmann::json& j, const char* key) {
  const std::vector<double> v = Get<std::vector<double>>(j, key);
  if (v.size() != 3) throw InputError(std::string("groom.json/scalp/") + key, "needs 3 numbers");
  return {v[0], v[1], v[2]};
}

}  // namespace

StrandFileReader::StrandFileReader(const std::string& path) : impl_(std::make_unique<Impl>(path)) {
  Impl& r = *impl_;
  StrandFileHeader& h = r.header;
  nlohmann::json j;
  try {
    j = ParseJsonText(r.zip.ReadWhole("groom.json", kMaxGroomJsonBytes));
  } catch (const InputError& e) {
    if (e.field().rfind("groom.json", 0) == 0) throw;
    Problem p = e.problem();
    p.field = "groom.json" + p.field;
    throw InputError(p);
  }
  if (!j.is_object() || j.value("format", "") != "flexkin strands") {
    throw InputError("groom.json/format",
                     std::string("is not \"flexkin strands\"; not ") + kFileKind);
  }
  h.name = Get<std::string>(j, "name");
  h.description = Get<std::string>(j, "description");
  h.dim = Get<int>(j, "dim");
  h.num_frames = Get<int64_t>(j, "num_frames");
  const std::string precision = Get<std::string>(j, "precision");
  h.float32 =
      ParseName<StrandPrecision>(precision, "groom.json/precision") == StrandPrecision::kFloat32;
  h.fps = Get<double>(j, "fps");
  h.method = Get<std::string>(j, "method");
  h.substeps = Get<int>(j, "substeps");
  h.pinned = Get<int>(j, "pinned");
  h.record_every = Get<int>(j, "record_every");
  const nlohmann::json scalp = Get<nlohmann::json>(j, "scalp");
  h.scalp.shape = Get<std::string>(scalp, "shape");
  h.scalp.center = GetVector(scalp, "center");
  h.scalp.radii = GetVector(scalp, "radii");
  for (const auto& [key, list] : {std::pair{"body_colliders", &h.body_colliders},
                                  std::pair{"world_colliders", &h.world_colliders}}) {
    const auto it = j.find(key);
    if (it == j.end()) continue;
    Problems problems;
    *list =
        ReadCollidersJson(*it, std::string("groom.json/") + key, h.dim, &problems, "", "seconds");
    ThrowIfAny(problems);
  }
  const nlohmann::json report = Get<nlohmann::json>(j, "report");
  if (const auto it = report.find("contact_link_steps"); it != report.end()) {
    r.report.contact_link_steps = Get<int64_t>(report, "contact_link_steps");
    const auto least = report.find("least_clearance");
    if (least != report.end() && !least->is_null()) {
      r.report.least_clearance = Get<double>(report, "least_clearance");
    }
  }
  if (const auto it = j.find("dynamics"); it != j.end()) {
    DynamicOptions d;
    const std::string name = Get<std::string>(*it, "projection");
    const NamedValue<Projection>* entry = FindName<Projection>(name);
    if (entry == nullptr) {
      throw InputError("groom.json/dynamics/projection",
                       "is \"" + name + "\", not a projection; not " + std::string(kFileKind));
    }
    d.projection = entry->value;
    const auto vector = [&](const char* key) {
      const std::vector<double> v = Get<std::vector<double>>(*it, key);
      if (static_cast<int>(v.size()) != h.dim) {
        throw InputError(std::string("groom.json/dynamics/") + key,
                         "has " + std::to_string(v.size()) + " numbers, not the file's dim " +
                             std::to_string(h.dim) + "; not " + std::string(kFileKind));
      }
      return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), h.dim));
    };
    d.gravity = vector("gravity");
    if (it->contains("wind")) d.wind = vector("wind");
    d.damping = Get<double>(*it, "damping");
    const nlohmann::json mass = Get<nlohmann::json>(*it, "mass");
    if (mass.is_array()) {
      const std::vector<double> m = Get<std::vector<double>>(*it, "mass");
      d.masses = Eigen::Map<const Eigen::VectorXd>(m.data(), static_cast<Eigen::Index>(m.size()));
    } else {
      d.mass_by_length = Get<std::string>(*it, "mass") == "by_length";
    }
    h.own_masses = it->contains("own_masses") && Get<bool>(*it, "own_masses");
    d.dftl_damping = Get<double>(*it, "dftl_damping");
    d.frame_rate = h.fps;
    h.dynamics = d;
    const nlohmann::json energy = Get<nlohmann::json>(report, "energy");
    if (!energy.is_array()) {
      throw InputError("groom.json/report/energy",
                       "is not an array; not " + std::string(kFileKind));
    }
    for (const nlohmann::json& e : energy) {
      if (!e.is_null() && !e.is_number()) {
        throw InputError("groom.json/report/energy",
                         "has " + e.dump() + ", not a number; not " + std::string(kFileKind));
      }
      r.report.energy.push_back(e.is_null() ? std::numeric_limits<double>::quiet_NaN()
                                            : e.get<double>());
    }
    r.report.failures = Get<int64_t>(report, "failures");
    r.report.contact_substeps = Get<int64_t>(report, "contact_substeps");
  }
  r.report.max_length_error = Get<double>(report, "max_length_error");
  r.report.seconds = Get<double>(report, "seconds");
  r.report.engine = Get<std::string>(report, "engine");
  r.report.threads = Get<int>(report, "threads");
  const int64_t strands = Get<int64_t>(j, "num_strands");
  if (strands < 0 || strands > (int64_t{1} << 31) || h.num_frames < 1 ||
      h.num_frames > (int64_t{1} << 40)) {
    throw InputError("groom.json/num_strands", "is out of range; not " + std::string(kFileKind));
  }

  ReadMember(&r.zip, "offsets.npy", "<i8", {U(strands + 1)}, &h.offsets);
  std::vector<double> lengths;
  const int64_t points = h.offsets.back();
  if (points - strands < 0 || points > (int64_t{1} << 40)) {
    throw InputError("offsets.npy", "last value out of range; not " + std::string(kFileKind));
  }
  ReadMember(&r.zip, "link_lengths.npy", "<f8", {U(points - strands)}, &lengths);
  h.link_lengths = Eigen::Map<const Eigen::VectorXd>(lengths.data(), U(lengths.size()));
  if (Problems problems = HeaderProblems(h); !problems.empty()) {
    problems.front().message += " (in the strand file)";
    ThrowIfAny(problems);
  }
  const uint64_t f = U(h.num_frames);
  std::vector<int64_t> frames;
  std::vector<double> times, rotation, translation;
  ReadMember(&r.zip, "frames.npy", "<i8", {f}, &frames);
  ReadMember(&r.zip, "times.npy", "<f8", {f}, &times);
  ReadMember(&r.zip, "body_rotation.npy", "<f8", {f, 3, 3}, &rotation);
  ReadMember(&r.zip, "body_translation.npy", "<f8", {f, 3}, &translation);
  r.info.resize(f);
  for (uint64_t k = 0; k < f; ++k) {
    StrandFrame& s = r.info[k];
    s.frame = frames[k];
    s.time = times[k];
    for (int a = 0; a < 3; ++a) {
      s.pose.translation[a] = translation[3 * k + a];
      for (int b = 0; b < 3; ++b) s.pose.rotation(a, b) = rotation[9 * k + 3 * a + b];
    }
    const std::string at = "[" + std::to_string(k) + "]";
    if (k > 0 && s.frame <= r.info[k - 1].frame) {
      throw InputError("frames.npy" + at, "is not above the previous frame number");
    }
    if (!std::isfinite(s.time)) throw InputError("times.npy" + at, "is not a finite number");
    if (!s.pose.rotation.allFinite() || !s.pose.translation.allFinite()) {
      throw InputError("body_rotation.npy" + at, "is not finite");
    }
  }
  r.points = std::make_unique<ZipReader::Member>(&r.zip, "points.npy");
  ExpectNpyShape(ReadNpyHeader(r.points.get(), "points.npy", h.float32 ? "<f4" : "<f8"),
                 "points.npy", {f, U(points), U(h.dim)}, kFileKind);
}

StrandFileReader::~StrandFileReader() = default;

const StrandFileHeader& StrandFileReader::header() const { return impl_->header; }
const StrandRunReport& StrandFileReader::report() const { return impl_->report; }
const std::vector<StrandFrame>& StrandFileReader::frame_info() const { return impl_->info; }

bool StrandFileReader::Next(StrandFrame* out) {
  Impl& r = *impl_;
  const StrandFileHeader& h = r.header;
  if (r.next >= h.num_frames) return false;
  const StrandFrame& info = r.info[static_cast<size_t>(r.next)];
  out->frame = info.frame;
  out->time = info.time;
  out->pose = info.pose;
  out->points.resize(h.num_points(), h.dim);
  const size_t count = static_cast<size_t>(out->points.size());
  if (h.float32) {
    r.row32.resize(count);
    r.points->Read(r.row32.data(), sizeof(float) * count);
    for (size_t k = 0; k < count; ++k) out->points.data()[k] = r.row32[k];
  } else {
    r.points->Read(out->points.data(), sizeof(double) * count);
  }
  for (size_t k = 0; k < count; ++k) {
    if (!std::isfinite(out->points.data()[k])) {
      throw InputError("points.npy[" + std::to_string(r.next) + "][" + std::to_string(k / h.dim) +
                           "][" + std::to_string(k % h.dim) + "]",
                       std::string("is not a finite number; not ") + kFileKind);
    }
  }
  if (++r.next == h.num_frames) r.points->Finish();
  return true;
}

bool IsStrandFile(const std::string& path) {
  try {
    ZipReader zip(path);
    return zip.Has("groom.json") && zip.Has("points.npy");
  } catch (...) {
    return false;
  }
}

std::string StrandMotionName(const StrandFileHeader& header) {
  if (!header.dynamics) return header.method;
  return std::string("dynamic, projection ") + ProjectionName(header.dynamics->projection);
}

}  // namespace flexkin
