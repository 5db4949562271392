// Soak: a long run of a 1,000-link 3D chain and of a 128-link arm (10 million steps each by
// default), showing that memory stays flat and that the link lengths and the arm's base stay
// within their bounds throughout. Not a timed test (docs/BENCHMARKS.md, "Long runs"); exits 1 if
// a bound is broken, so that it can also be run as a check.
//   build/bench/soak [--steps N] [--only chain|arm] [--lines L]
// Every step is checked: the chain's largest relative link-length error |(|x_i - x_{i-1}| - L_i)|
// / L_i over every link (bound 1e-13: rounding, no drift), and the arm's links (the same bound)
// and its base (exactly at the model's base). Memory: the process's resident set (VmRSS) at L
// evenly spaced lines; "flat" means it grows by at most 1 MiB between the first line (after the
// first 1% of the steps) and the last.
#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "flexkin/flexkin.h"

namespace {

constexpr double kLengthBound = 1e-13;
constexpr double kMemoryGrowthBound = 1.0;  // MiB

// The resident set of this process (MiB), from /proc/self/status.
double ResidentMiB() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  }
  return -1.0;
}

// The largest relative link-length error of `points` against `lengths` (links of length 0, the
// arm's coincident joints, are held to an absolute 1e-13 of the mean instead).
double LengthError(const flexkin::Points& points, const Eigen::VectorXd& lengths) {
  double worst = 0.0;
  const double mean = lengths.mean();
  for (Eigen::Index k = 0; k < lengths.size(); ++k) {
    const double d = (points.row(k + 1) - points.row(k)).norm();
    const double scale = lengths[k] > 0.0 ? lengths[k] : mean;
    worst = std::max(worst, std::abs(d - lengths[k]) / scale);
  }
  return worst;
}

// A bounded, non-periodic leader path: each coordinate a sine of its own (incommensurate)
// frequency, so that over millions of steps the end never settles into one repeated motion.
Eigen::Vector3d Wander(double t, const Eigen::Vector3d& center, double radius) {
  return center + radius * Eigen::Vector3d(std::sin(t), std::sin(std::sqrt(2.0) * t + 0.3),
                                           std::sin(std::sqrt(3.0) * t + 1.1));
}

struct Progress {
  const char* what;
  long long steps;
  int lines;
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  double first_rss = -1.0, last_rss = -1.0, max_rss = 0.0;
  double worst_length = 0.0, worst_base = 0.0;
  long long unreached = 0;

  void Header() const {
    std::printf("\n%s: %lld steps\n%12s %10s %10s %14s %14s %10s\n", what, steps, "step", "seconds",
                "RSS MiB", "length error", "base error", "unreached");
  }
  // Called after step s (1-based).
  void Maybe(long long s) {
    const long long every = std::max(1LL, steps / lines);
    const long long warm = std::max(1LL, steps / 100);
    if (s != warm && s % every != 0 && s != steps) return;
    const double rss = ResidentMiB();
    if (s >= warm && first_rss < 0.0) first_rss = rss;
    last_rss = rss;
    max_rss = std::max(max_rss, rss);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%12lld %10.1f %10.2f %14.3g %14.3g %10lld\n", s, seconds, rss, worst_length,
                worst_base, unreached);
    std::fflush(stdout);
  }
  bool Verdict() const {
    const double growth = last_rss - first_rss;
    const bool ok =
        worst_length <= kLengthBound && worst_base == 0.0 && growth <= kMemoryGrowthBound;
    std::printf(
        "%s: %s. Largest length error %.3g (bound %.0e), base error %.3g (bound 0), memory %.2f "
        "MiB after 1%% of the steps, %.2f MiB at the end (growth %.2f MiB, bound %.1f), peak "
        "%.2f MiB; %lld steps unreached\n",
        what, ok ? "within bounds" : "BOUND BROKEN", worst_length, kLengthBound, worst_base,
        first_rss, last_rss, growth, kMemoryGrowthBound, max_rss, unreached);
    return ok;
  }
};

// A 1,000-link helix whose leading end wanders within a ball of 20 link lengths: tractrix
// steps (the SIMD engine), one sub-step, each step about 0.05 link lengths.
bool SoakChain(long long steps, int lines) {
  flexkin::HelixDef def;
  def.links = 1000;
  def.link_length = 1.0;
  def.radius = 5.0;
  def.pitch = 3.0;
  const flexkin::Chain chain = flexkin::MakeChain(flexkin::MakeHelix(def));
  const flexkin::Stepper stepper = flexkin::MakeStepper(flexkin::Method::kTractrix, chain);
  flexkin::Points points = chain.points;
  const Eigen::Vector3d center = points.row(0).transpose();
  Progress progress{"chain (1000 links, 3D, tractrix)", steps, lines};
  progress.Header();
  const double dt = 0.05 / 20.0;  // the leader moves about 0.05 link lengths a step
  for (long long s = 1; s <= steps; ++s) {
    const Eigen::Vector3d target =
        Wander(dt * double(s), center, 20.0) - Wander(0.0, center, 20.0) + center;
    flexkin::MoveLeader(stepper, target, 1, &points);
    progress.worst_length = std::max(progress.worst_length, LengthError(points, stepper.lengths));
    progress.Maybe(s);
  }
  return progress.Verdict();
}

// A 128-link spatial arm (spherical joints, method newton, tolerance 1e-10) whose end effector
// wanders within a ball of 16 link lengths around a point at 3/4 of its reach.
bool SoakArm(long long steps, int lines) {
  const flexkin::ArmModel model = flexkin::StraightArm(3, 128, 1.0);
  flexkin::ArmOptions options;
  flexkin::ArmState state = flexkin::InitialState(model);
  const Eigen::Vector3d start = state.points.row(128).transpose();
  const Eigen::Vector3d center(96.0, 0.0, 0.0);
  Progress progress{"arm (128 links, spherical joints, newton)", steps, lines};
  progress.Header();
  // The first 1,000 steps bring the end effector from its straight start to the wander.
  const double dt = 0.1 / 16.0;  // about 0.1 link lengths a step
  const long long approach = std::min(steps, 1000LL);
  for (long long s = 1; s <= steps; ++s) {
    const Eigen::Vector3d on_path = Wander(dt * double(s), center, 16.0);
    const Eigen::Vector3d target =
        s <= approach ? Eigen::Vector3d(start + (on_path - start) * (double(s) / approach))
                      : on_path;
    flexkin::ArmStepReport step = flexkin::ArmStep(model, state, target, options);
    progress.unreached += !step.reached;
    progress.worst_length =
        std::max(progress.worst_length, LengthError(step.state.points, model.link_lengths));
    progress.worst_base =
        std::max(progress.worst_base, (step.state.points.row(0).transpose() - model.base).norm());
    state = std::move(step.state);
    progress.Maybe(s);
  }
  return progress.Verdict();
}

}  // namespace

int main(int argc, char** argv) {
  long long steps = 10'000'000;
  int lines = 20;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--steps" && i + 1 < argc) {
      steps = std::atoll(argv[++i]);
    } else if (arg == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (arg == "--lines" && i + 1 < argc) {
      lines = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr,
                   "usage: soak [--steps N >= 1] [--only chain|arm] [--lines L >= 1]; got "
                   "\"%s\"\n",
                   arg.c_str());
      return 2;
    }
  }
  if (steps < 1 || lines < 1 || !(only.empty() || only == "chain" || only == "arm")) {
    std::fprintf(stderr, "soak: --steps and --lines must be >= 1, --only chain or arm\n");
    return 2;
  }
  bool ok = true;
  if (only != "arm") ok &= SoakChain(steps, lines);
  if (only != "chain") ok &= SoakArm(steps, lines);
  return ok ? 0 : 1;
}
