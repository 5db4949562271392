// A run's options (RunOptions::Validate) and how many frames it records.
#include <algorithm>
#include <cmath>
#include <string>

#include "flexkin/error.h"
#include "flexkin/run.h"

namespace flexkin {

Problems RunOptions::Validate() const {
  Problems problems;
  if (substeps < 1) {
    problems.emplace_back("substeps", std::to_string(substeps) + " is not valid; must be >= 1",
                          std::to_string(substeps), ">= 1");
  }
  if (record_every < 1) {
    problems.emplace_back("record_every",
                          std::to_string(record_every) + " is not valid; must be >= 1",
                          std::to_string(record_every), ">= 1");
  }
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    problems.emplace_back("tolerance",
                          FormatNumber(tolerance) +
                              " is not valid; must be a finite number >= 0 (0 turns accuracy "
                              "control off)",
                          FormatNumber(tolerance), "a finite number >= 0");
  } else if (tolerance > 0.0 && MethodOrder(method) == 0) {
    problems.emplace_back("tolerance",
                          std::string("accuracy control is available for the tractrix and ftl "
                                      "methods; with \"") +
                              MethodName(method) + "\" set it to 0 and choose the sub-steps",
                          FormatNumber(tolerance), "0 with this method");
  }
  if (tolerance > 0.0 && max_substeps < 2) {
    problems.emplace_back("max_substeps",
                          std::to_string(max_substeps) +
                              " is not valid; accuracy control compares two runs and needs "
                              "max_substeps >= 2",
                          std::to_string(max_substeps), ">= 2");
  } else if (max_substeps < substeps && substeps >= 1) {
    problems.emplace_back("max_substeps",
                          std::to_string(max_substeps) + " is not valid; must be >= substeps (" +
                              std::to_string(substeps) + ")",
                          std::to_string(max_substeps), ">= substeps");
  }
  if (method == Method::kOverall) AppendNested("overall", overall.Validate(), &problems);
  for (size_t i = 0; i < colliders.size(); ++i) {
    const Problems collider = CheckCollider(colliders[i], "colliders[" + std::to_string(i) + "]");
    problems.insert(problems.end(), collider.begin(), collider.end());
  }
  const bool moving =
      std::any_of(colliders.begin(), colliders.end(), [](const Collider& c) { return c.motion; });
  if (moving && method == Method::kOverall) {
    // With static colliders the L2 metric's still points are a tail (overall/contact_step.cc);
    // a collider that moves into the chain can leave them anywhere along it.
    for (const char* term : {"l2", "l2_weighted"}) {
      const double weight =
          std::string(term) == "l2" ? overall.weights.l2 : overall.weights.l2_weighted;
      if (weight > 0.0) {
        problems.emplace_back(std::string("overall.weights.") + term,
                              "the overall method takes the L2 metric with colliders that do not "
                              "move; with a moving collider (\"motion\") its still points may lie "
                              "anywhere along the chain, which is not solved yet: set it to 0 (a "
                              "smooth metric), or use \"tractrix\"",
                              FormatNumber(weight), "0 with moving colliders");
      }
    }
  }
  if (!(std::isfinite(link_radius) && link_radius >= 0.0)) {
    problems.push_back(
        Problem::Invalid("link_radius", FormatNumber(link_radius), "a finite number >= 0"));
  }
  if (!colliders.empty() && tolerance > 0.0) {
    problems.emplace_back("tolerance",
                          "accuracy control does not account for colliders; set it to 0 and "
                          "choose the sub-steps",
                          FormatNumber(tolerance), "0 with colliders");
  }
  return problems;
}

int64_t CountRecordedFrames(int64_t num_steps, int record_every) {
  if (num_steps <= 0) return 1;
  const int64_t every = std::max(record_every, 1);
  return 1 + num_steps / every + (num_steps % every != 0 ? 1 : 0);
}

void FrameRecorder::Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) {
  frames.Add(step, points, link_angles);
}

}  // namespace flexkin
