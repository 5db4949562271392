// Result files as NumPy .npz archives (docs/result-format.md, "npz"): the streaming writer
// (ResultFileWriter's npz part) and the reader (ReadResultFile's npz part). The ZIP and .npy
// structures are in io/npz.cc.
#include <cstring>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "io/atomic_file.h"
#include "io/json_file.h"
#include "io/npz.h"
#include "io/result_json.h"
#include "io/result_writers.h"

namespace flexkin {
namespace {

static_assert(Points::IsRowMajor, "a frame's points are written as they lie in memory");
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error ".npz results are written as little-endian doubles ('<f8') from memory"
#endif

constexpr uint64_t kMaxResultJsonBytes = 64u << 20;

class NpzResultWriter : public ResultFileWriter::Impl {
 public:
  NpzResultWriter(const std::string& path, const ResultHeader& header)
      : file_(path),
        zip_(&file_),
        header_(header),
        n_(static_cast<uint64_t>(header.lengths.size())) {
    WriteArray("link_lengths.npy", header.lengths);
    frames_header_length_ =
        NpyHeader("<f8", {static_cast<uint64_t>(std::numeric_limits<int64_t>::max()), n_ + 1,
                          static_cast<uint64_t>(header.dim)})
            .size();
    zip_.BeginMember("frames.npy", FramesHeader(0));
  }

  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) override {
    const bool angles = link_angles.size() > 0;
    if (steps_.empty()) {
      have_angles_ = angles;
      if (angles) {
        scratch_ =
            std::make_unique<ScratchFile>(file_.directory(), "cannot write '" + file_.path() + "'");
      }
    } else if (angles != have_angles_) {
      throw InputError(
          "frames[" + std::to_string(steps_.size()) + "].link_angles",
          "has " + std::to_string(link_angles.size()) + " values and frame 0 " +
              (have_angles_ ? std::to_string(n_) : std::string("none")) +
              "; an .npz result holds link angles for every frame or for none; nothing was "
              "written");
    }
    zip_.Write(points.data(), sizeof(double) * static_cast<size_t>(points.size()));
    if (angles) scratch_->Write(link_angles.data(), sizeof(double) * n_);
    steps_.push_back(step);
    file_.Check();
  }

  void Commit(const RunResult& result) override {
    const uint64_t frames = steps_.size();
    zip_.EndMember(FramesHeader(frames));
    zip_.BeginMember("steps.npy", NpyHeader("<i8", {frames}));
    zip_.Write(steps_.data(), sizeof(int64_t) * steps_.size());
    zip_.EndMember();
    if (have_angles_) {
      zip_.BeginMember("link_angles.npy", NpyHeader("<f8", {frames, n_}));
      scratch_->CopyTo([this](const char* data, size_t size) { zip_.Write(data, size); });
      zip_.EndMember();
      scratch_.reset();
    }
    WriteArray("l2_per_step.npy", result.metrics.l2_per_step);
    WriteArray("l2_weighted_per_step.npy", result.metrics.l2_weighted_per_step);
    WriteArray("path_length.npy", result.metrics.path_length);
    std::string text = "{\n";
    AppendResultHeaderJson(header_, false, &text);
    text += "\"num_frames\": " + std::to_string(frames) + ",\n";
    text += std::string("\"link_angles\": ") + (have_angles_ ? "true" : "false") + ",\n";
    AppendResultSummaryJson(result, false, &text);
    text += "\n}\n";
    zip_.AddMember("result.json", text);
    zip_.Finish();
    file_.Commit();
  }

 private:
  std::string FramesHeader(uint64_t frames) const {
    return NpyHeader("<f8", {frames, n_ + 1, static_cast<uint64_t>(header_.dim)},
                     frames_header_length_);
  }
  void WriteArray(const std::string& name, const Eigen::VectorXd& v) {
    zip_.BeginMember(name, NpyHeader("<f8", {static_cast<uint64_t>(v.size())}));
    zip_.Write(v.data(), sizeof(double) * static_cast<size_t>(v.size()));
    zip_.EndMember();
  }

  AtomicFile file_;
  ZipWriter zip_;
  ResultHeader header_;
  uint64_t n_;
  size_t frames_header_length_ = 0;
  std::vector<int64_t> steps_;
  bool have_angles_ = false;
  std::unique_ptr<ScratchFile> scratch_;
};

// A 1-dimensional float64 member of `size` values (any size if < 0).
Eigen::VectorXd ReadVectorMember(ZipReader* zip, const std::string& name, int64_t size) {
  ZipReader::Member member(zip, name);
  const NpyArray a = ReadNpyHeader(&member, name, "<f8");
  if (a.shape.size() != 1 || (size >= 0 && a.shape[0] != static_cast<uint64_t>(size))) {
    std::string shape;
    for (uint64_t d : a.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    throw InputError(name, "has shape (" + shape + "); expected (" +
                               (size >= 0 ? std::to_string(size) : std::string("N")) +
                               ",); not a valid .npz result file");
  }
  Eigen::VectorXd v(static_cast<Eigen::Index>(a.count));
  member.Read(v.data(), sizeof(double) * a.count);
  member.Finish();
  return v;
}

void ExpectShape(const NpyArray& a, const std::string& name, const std::vector<uint64_t>& shape) {
  ExpectNpyShape(a, name, shape, "a valid .npz result file");
}

}  // namespace

std::unique_ptr<ResultFileWriter::Impl> MakeNpzResultWriter(const std::string& path,
                                                            const ResultHeader& header) {
  return std::make_unique<NpzResultWriter>(path, header);
}

ResultFile ReadNpzResult(const std::string& path) {
  ZipReader zip(path);
  if (!zip.Has("result.json") && zip.Has("groom.json") && zip.Has("points.npy")) {
    // The other .npz that flexkin writes (its members as IsStrandFile tests them,
    // io/strand_file.cc): say what it is and what reads it, not that result.json is missing.
    throw InputError(
        Problem("",
                "is a strand file (the output of a groom run, docs/strands.md), not a chain "
                "result; read it with numpy.load in Python or StrandFileReader in C++ "
                "(flexkin/strand_file.h), or draw it with `flexkin render`"));
  }
  ResultFile file;
  RunResult& r = file.result;
  nlohmann::json summary;
  try {
    summary = ParseJsonText(zip.ReadWhole("result.json", kMaxResultJsonBytes));
  } catch (const InputError& e) {
    if (e.field().rfind("result.json", 0) == 0) throw;
    Problem p = e.problem();
    p.field = "result.json" + p.field;
    throw InputError(p);
  }
  ResultArrays arrays;
  arrays.lengths = ReadVectorMember(&zip, "link_lengths.npy", -1);
  try {
    // The arrays' sizes are checked below, against the lengths and the steps.
    ReadResultSummary(summary, &arrays, &file);
  } catch (const InputError& e) {
    Problem p = e.problem();
    p.field = "result.json" + p.field;
    throw InputError(p);
  }
  const uint64_t n = static_cast<uint64_t>(r.lengths.size());
  r.metrics.path_length = ReadVectorMember(&zip, "path_length.npy", static_cast<int64_t>(n + 1));
  r.metrics.l2_per_step = ReadVectorMember(&zip, "l2_per_step.npy", r.num_steps);
  r.metrics.l2_weighted_per_step = ReadVectorMember(&zip, "l2_weighted_per_step.npy", r.num_steps);

  const uint64_t dim = static_cast<uint64_t>(file.dim);
  ZipReader::Member frames(&zip, "frames.npy");
  const NpyArray fa = ReadNpyHeader(&frames, "frames.npy", "<f8");
  const uint64_t count = fa.shape.empty() ? 0 : fa.shape[0];
  ExpectShape(fa, "frames.npy", {count, n + 1, dim});
  if (count == 0) {
    throw InputError("frames.npy", "has no frames; expected at least the initial frame");
  }
  ZipReader::Member steps(&zip, "steps.npy");
  ExpectShape(ReadNpyHeader(&steps, "steps.npy", "<i8"), "steps.npy", {count});
  std::unique_ptr<ZipReader::Member> angles;
  if (zip.Has("link_angles.npy")) {
    angles = std::make_unique<ZipReader::Member>(&zip, "link_angles.npy");
    ExpectShape(ReadNpyHeader(angles.get(), "link_angles.npy", "<f8"), "link_angles.npy",
                {count, n});
  }
  // Each member straight into the dense arrays of the result, in one read.
  r.frames.Resize(static_cast<int64_t>(count), static_cast<int64_t>(n + 1), file.dim,
                  angles != nullptr);
  frames.Read(r.frames.mutable_points_data(), sizeof(double) * count * (n + 1) * dim);
  steps.Read(r.frames.mutable_steps(), sizeof(int64_t) * count);
  if (angles) angles->Read(r.frames.mutable_link_angles_data(), sizeof(double) * count * n);
  frames.Finish();
  steps.Finish();
  if (angles) angles->Finish();
  // The one check of results (finite numbers, increasing steps, positive lengths), its member
  // path naming the value ("frames[3].points[2][1]").
  if (Problems problems = ValidateResult(r, file.dim); !problems.empty()) {
    problems.front().message += " (in the .npz result)";
    ThrowIfAny(problems);
  }
  return file;
}

}  // namespace flexkin
