#pragma once
// What the result writers share (src/io/result_writer.cc: JSON and CSV; src/io/result_npz.cc:
// npz): the streaming writer's implementations and the JSON text of a result's header and summary.
// Private to the library.

#include <cstdint>
#include <memory>
#include <string>

#include "flexkin/result_io.h"

namespace flexkin {

// A ResultFileWriter's format-specific part. Add and Commit are called after the shared checks.
class ResultFileWriter::Impl {
 public:
  virtual ~Impl() = default;
  virtual void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) = 0;
  virtual void Commit(const RunResult& result) = 0;
};

std::unique_ptr<ResultFileWriter::Impl> MakeNpzResultWriter(const std::string& path,
                                                            const ResultHeader& header);

// %.17g, and negative zero as "-0.0".
void AppendJsonDouble(double x, std::string* out);
// "format", "version", "scenario" (if any), "method", "dim", "num_links" and, with
// `with_lengths`, "link_lengths": the keys of a result document known before its frames, each
// followed by ",\n".
void AppendResultHeaderJson(const ResultHeader& header, bool with_lengths, std::string* out);
// "num_steps", "substeps", "seconds", "accuracy", "overall" (method overall) and "metrics" (with
// the per-step and per-point arrays if `with_arrays`): the keys of a result document known at its
// end, separated by ",\n", without a trailing separator.
void AppendResultSummaryJson(const RunResult& result, bool with_arrays, std::string* out);

}  // namespace flexkin
