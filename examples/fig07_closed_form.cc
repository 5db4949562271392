// Paper Fig. 7 / eq. (23): a straight link whose leading end is pulled in a straight line, with
// the trailing end initially perpendicular to the pull. Runs the scenario with the library and
// compares every recorded trailing-end position with the closed form
//   x(p) = p - L tanh(p/L),  y(p) = L sech(p/L)
// in the frame of the pull (x along the pull from the head's start, y toward the initial tail).
// Usage: fig07_closed_form [scenario.json]   (default examples/fig07_straight_link.json)
#include <cmath>
#include <cstdio>
#include <exception>

#include "flexkin/run.h"
#include "flexkin/scenario.h"

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "examples/fig07_straight_link.json";
  try {
    const flexkin::Scenario scenario = flexkin::LoadScenarioFile(path);
    const flexkin::Chain& chain = scenario.chain;
    if (chain.num_links() != 1) {
      std::fprintf(stderr, "%s: expected one link, got %d\n", path, chain.num_links());
      return 1;
    }
    const Eigen::VectorXd head0 = chain.points.row(0).transpose();
    const Eigen::VectorXd tail0 = chain.points.row(1).transpose();
    const Eigen::VectorXd pull = scenario.leader_steps.bottomRows(1).transpose() - head0;
    const Eigen::VectorXd u = pull.normalized();
    const Eigen::VectorXd w = (tail0 - head0).normalized();
    if (std::fabs(u.dot(w)) > 1e-12) {
      std::fprintf(stderr, "%s: eq. (23) needs the link perpendicular to the pull\n", path);
      return 1;
    }
    const double length = chain.lengths[0];
    const flexkin::RunResult result = flexkin::Run(chain, scenario.leader_steps, scenario.options);
    double worst = 0.0;
    for (const flexkin::Frame& frame : result.frames) {
      const Eigen::VectorXd head = frame.points.row(0).transpose();
      const double p = (head - head0).norm();
      const Eigen::VectorXd expected =
          head0 + (p - length * std::tanh(p / length)) * u + length / std::cosh(p / length) * w;
      worst = std::fmax(worst, (frame.points.row(1).transpose() - expected).norm() / length);
    }
    std::printf(
        "Fig. 7 (eq. 23): %zu frames, pull %.6g link lengths; largest distance of the "
        "trailing end from the closed form: %.3g link lengths; %s\n",
        result.frames.size(), pull.norm() / length, worst, result.BriefReport().c_str());
    return worst < 1e-12 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", path, e.what());
    return 1;
  }
}
