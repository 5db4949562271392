// The size of a run's output before the run (flexkin/result_io.h, EstimateResultSize): frames
// counted exactly, bytes per number estimated (docs/result-format.md, "Output size").
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "flexkin/result_io.h"

namespace flexkin {
namespace {

// JSON and CSV: 17 significant digits, a sign, a decimal point, an exponent ("e-07") and a
// separator; typical numbers take 19 to 23 bytes, so the estimate errs on the large side.
constexpr double kTextBytesPerNumber = 24.0;
constexpr double kBinaryBytesPerNumber = 8.0;

uint64_t Bytes(double x) {
  if (!(x < 1.8e19)) return std::numeric_limits<uint64_t>::max();
  return static_cast<uint64_t>(std::ceil(std::max(0.0, x)));
}

double Digits(double x) { return x < 10 ? 1 : std::floor(std::log10(x)) + 1; }

}  // namespace

uint64_t ResultSizeEstimate::bytes(ResultFileFormat format) const {
  return format == ResultFileFormat::kNpz ? npz_bytes : json_bytes;
}

ResultSizeEstimate EstimateResultSize(int num_links, int dim, int64_t num_steps,
                                      const RunOptions& options) {
  ResultSizeEstimate e;
  e.frames = CountRecordedFrames(num_steps, options.record_every);
  e.link_angles = options.link_angles;
  const double n = std::max(num_links, 0), d = dim, f = static_cast<double>(e.frames);
  const double steps = static_cast<double>(std::max<int64_t>(num_steps, 0));
  const double angles = e.link_angles ? n : 0.0;
  // Numbers outside the frames: link lengths, path lengths, per-step metrics.
  const double other = n + (n + 1) + 2 * steps;
  // JSON: per point "[x,y]," (3 bytes of brackets and commas), per frame its keys and step.
  const double json_frame =
      48 + (n + 1) * (d * kTextBytesPerNumber + 3) + angles * kTextBytesPerNumber;
  e.json_bytes = Bytes(1024 + other * kTextBytesPerNumber + f * json_frame);
  // npz: every member's ZIP headers and .npy header (about 200 bytes each), result.json, the
  // central directory; then 8 bytes per number and per step number.
  const double npz_frame = ((n + 1) * d + angles) * kBinaryBytesPerNumber + 8;
  e.npz_bytes = Bytes(3072 + other * kBinaryBytesPerNumber + f * npz_frame);
  // CSV: per point "step,point,x,y\n".
  const double csv_row = Digits(steps) + Digits(n) + 3 + d * (kTextBytesPerNumber + 1);
  e.csv_bytes = Bytes(32 + f * (n + 1) * csv_row);
  // FrameRecorder: per frame the Frame (its matrices' headers) and heap blocks (16 bytes of
  // allocator overhead each), the points and the link angles.
  const double recorder_frame =
      static_cast<double>(sizeof(Frame)) + 32 + ((n + 1) * d + angles) * sizeof(double);
  e.recorder_bytes = Bytes(f * recorder_frame);
  return e;
}

uint64_t EstimateResultBytes(int num_links, int dim, int64_t num_steps, const RunOptions& options,
                             ResultFileFormat format) {
  return EstimateResultSize(num_links, dim, num_steps, options).bytes(format);
}

}  // namespace flexkin
