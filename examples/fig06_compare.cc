// Paper Fig. 6 / Sec. 5.1: the parabola y = x^2 in 20 links of 0.25 pulled 0.7 at 45 degrees, by
// several strategies (sequential or overall, single-step or 5 steps of 0.14). The paper takes the
// multi-step sequential result as the reference and reports each strategy's distance from it
// (0.6347 single-step sequential, 1.6007 multi-step overall, 1.6982 single-step overall; its
// set-up is not fully stated, and docs/paper-reproduction.md says what is assumed here).
// Prints, for each scenario after the first (the reference), the distance of its final
// configuration from the reference's (sum over points, arc-length weighted, largest), and the
// L2 metric of each motion.
// Usage: fig06_compare REFERENCE.json OTHER.json...
#include <cstdio>
#include <exception>
#include <string>

#include "flexkin/run.h"
#include "flexkin/scenario.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: fig06_compare REFERENCE.json OTHER.json...\n");
    return 2;
  }
  try {
    auto run = [](const char* path) {
      const flexkin::Scenario s = flexkin::LoadScenarioFile(path);
      return flexkin::Run(s.chain, s.leader_steps, s.options);
    };
    const flexkin::RunResult reference = run(argv[1]);
    const flexkin::Points& ref = reference.frames.back().points;
    std::printf("Fig. 6 / Sec. 5.1, reference %s: L2 metric of the motion %.6f\n", argv[1],
                reference.metrics.l2_total);
    for (int a = 2; a < argc; ++a) {
      const flexkin::RunResult other = run(argv[a]);
      const flexkin::Points& x = other.frames.back().points;
      if (x.rows() != ref.rows() || x.cols() != ref.cols()) {
        std::fprintf(stderr, "%s: a different chain than the reference\n", argv[a]);
        return 1;
      }
      const Eigen::VectorXd gap = (x - ref).rowwise().norm();
      double weighted = 0.0;
      for (Eigen::Index j = 0; j < gap.size(); ++j) {
        const double left = j > 0 ? other.lengths[j - 1] : 0.0;
        const double right = j < other.lengths.size() ? other.lengths[j] : 0.0;
        weighted += 0.5 * (left + right) * gap[j];
      }
      std::printf(
          "  %s (%s): distance from the reference: sum over points %.6f, arc-length "
          "weighted %.6f, largest %.6f; L2 metric of the motion %.6f\n",
          argv[a], flexkin::MethodName(other.method), gap.sum(), weighted, gap.maxCoeff(),
          other.metrics.l2_total);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
