// What a run prints about itself: RunResult::BriefReport and FullReport.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "flexkin/run.h"

namespace flexkin {
namespace {

std::string Format(const char* fmt, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

}  // namespace

std::string RunResult::BriefReport() const {
  std::ostringstream out;
  if (dynamics.enabled) {
    out << "dynamic, projection " << dynamics.projection << ": " << lengths.size() << " links, "
        << num_steps << " frames at " << Format("%.6g", dynamics.frame_rate) << " fps x "
        << dynamics.substeps << " sub-steps, max relative length error "
        << Format("%.3g", metrics.max_relative_length_error);
    if (dynamics.energy.size() > 0) {
      out << ", energy " << Format("%.6g", dynamics.energy[0]) << " at the start, "
          << Format("%.6g", dynamics.energy[dynamics.energy.size() - 1]) << " at the end";
    }
    if (dynamics.failures > 0) out << ", " << dynamics.failures << " sub-steps' solves failed";
    if (dynamics.contact_substeps > 0) {
      out << ", " << dynamics.contact_substeps << " contact sub-steps";
      if (dynamics.contact_solves + dynamics.contact_solve_failures > 0) {
        out << " (" << dynamics.contact_solves << " solved with the contacts, "
            << dynamics.contact_solve_failures << " pushed out)";
      }
    }
    out << ", " << Format("%.3g", seconds) << " s";
    return out.str();
  }
  out << MethodName(method) << ": " << lengths.size() << " links, " << num_steps
      << " leader steps x " << accuracy.substeps << " sub-steps, max relative length error "
      << Format("%.3g", metrics.max_relative_length_error) << ", L2 total "
      << Format("%.10g", metrics.l2_total) << " (arc-length weighted "
      << Format("%.10g", metrics.l2_weighted_total) << ")";
  if (method == Method::kOverall) {
    out << ", overall solver: " << overall.solves - overall.failures << "/" << overall.solves
        << " steps converged, " << overall.iterations << " iterations (at most "
        << overall.max_iterations << " per step)";
    if (overall.failures > 0) out << ", FIRST FAILURE " << overall.first_failure;
  }
  if (contacts.num_colliders > 0 && !path.enabled) {
    out << ", " << contacts.num_colliders
        << (contacts.num_colliders == 1 ? " collider: " : " colliders: ")
        << contacts.contact_link_steps << " link steps in contact, least clearance "
        << Format("%.3g", contacts.least_clearance) << " of a link";
  }
  if (path.enabled) {
    out << ", on the head's path: largest deviation " << Format("%.3g", path.max_deviation)
        << ", largest tip error " << Format("%.3g", path.max_tip_error);
    if (contacts.num_colliders > 0) {
      out << ", least clearance " << Format("%.4g", path.least_clearance) << " at leader step "
          << path.least_clearance_step
          << (path.least_clearance < 0.0 ? " (THE BODY PASSES THROUGH A COLLIDER)" : "");
    }
  }
  if (accuracy.enabled) {
    out << ", estimated error " << Format("%.3g", accuracy.estimated_error)
        << (accuracy.met ? " (tolerance met)" : " (TOLERANCE NOT MET)");
  }
  out << ", " << Format("%.3g", seconds) << " s";
  return out.str();
}

std::string RunResult::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  // Streamed runs keep no frames here; the run counted them.
  const int64_t recorded = frames.empty() ? recorded_frames : static_cast<int64_t>(frames.size());
  out << "  recorded frames: " << recorded << "\n";
  out << "  path length per point (leading end first):";
  const Eigen::Index n = metrics.path_length.size();
  // Long chains: print about 20 evenly spaced points so the profile fits on a screen.
  const Eigen::Index stride = std::max<Eigen::Index>(1, n / 20);
  for (Eigen::Index j = 0; j < n; j += stride) {
    out << (j % (8 * stride) == 0 ? "\n    " : " ") << "[" << j << "] "
        << Format("%.6g", metrics.path_length[j]);
  }
  if ((n - 1) % stride != 0)
    out << " [" << n - 1 << "] " << Format("%.6g", metrics.path_length[n - 1]);
  out << "\n";
  const Eigen::VectorXd a =
      frames.empty() ? final_link_angles : Eigen::VectorXd(frames.back().link_angles);
  if (a.size() > 0) {
    out << "  final link angles to the pull, degrees: first " << Format("%.4g", a[0] * 180 / M_PI)
        << ", largest " << Format("%.4g", a.maxCoeff() * 180 / M_PI) << ", last "
        << Format("%.4g", a[a.size() - 1] * 180 / M_PI) << "\n";
  }
  return out.str();
}

}  // namespace flexkin
