// robot_compare SCENARIO.json OUT_PREFIX: one robot scenario (docs/robot-format.md) tracked by
// flexkin's tractrix step (TrackPath, fixed base) and by the Jacobian pseudo-inverse (Orocos
// KDL's ChainIkSolverPos_NR + ChainIkSolverVel_pinv, testing/kdl_peer.h), as in the
// predecessors' experiment (Ravi et al. 2010; examples/robot_ravi_*.json, docs/robots.md).
// Writes OUT_PREFIX.svg and OUT_PREFIX.png (joint angles over the path for both methods and each
// joint's total motion) and OUT_PREFIX.csv (both joint trajectories), and prints the per-joint
// total motion. Exit 0; 1 on bad input; 3 if a method missed a target (outputs still written).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "arm_metrics.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/urdf.h"
#include "io/atomic_file.h"
#include "kdl_peer.h"
#include "render/axes.h"
#include "render/canvas.h"

namespace {

using flexkin::JointAngles;
using flexkin::render::Align;
using flexkin::render::Axes;
using flexkin::render::Canvas;
using flexkin::render::Rect;
using flexkin::render::TextStyle;

constexpr double kDeg = 180.0 / M_PI;

struct Series {
  std::string title;
  std::vector<JointAngles> angles;  // the start, then one per step
  Eigen::VectorXd motion;           // per joint, rad
};

// The joint angles made continuous along the path (a joint that turns through +-pi keeps
// counting instead of jumping by 2 pi), for the plots; the CSV keeps flexkin's (-pi, pi].
std::vector<JointAngles> Unwrapped(const std::vector<JointAngles>& angles) {
  std::vector<JointAngles> out = angles;
  for (size_t i = 1; i < out.size(); ++i) {
    const Eigen::VectorXd step = out[i].angle - angles[i - 1].angle;
    for (Eigen::Index j = 0; j < step.size(); ++j) {
      out[i].angle[j] = out[i - 1].angle[j] + std::remainder(step[j], 2.0 * M_PI);
    }
  }
  return out;
}

// Joint angles (deg) over the steps, one line per joint coloured from the base (dark) to the end
// effector (yellow). y0, y1: multiples of y_step (deg).
void DrawAngles(cairo_t* cr, double ui, const Rect& area, const Series& s, double y0, double y1,
                double y_step) {
  const int steps = static_cast<int>(s.angles.size()) - 1;
  const int n = static_cast<int>(s.angles[0].angle.size());
  Axes axes(area, 0.0, steps, y0, y1);
  axes.SetIntegerX();
  axes.SetYTickStep(y_step);
  axes.Draw(cr, ui, "step", "joint angle (deg)");
  axes.Clip(cr);
  for (int j = 0; j < n; ++j) {
    flexkin::render::SetColor(cr, flexkin::render::Viridis(n > 1 ? 0.9 * j / (n - 1) : 0.0));
    cairo_set_line_width(cr, 2.0 * ui);
    for (int i = 0; i <= steps; ++i) {
      const double x = axes.X(i), y = axes.Y(s.angles[i].angle[j] * kDeg);
      i == 0 ? cairo_move_to(cr, x, y) : cairo_line_to(cr, x, y);
    }
    cairo_stroke(cr);
  }
  cairo_reset_clip(cr);
  TextStyle title;
  title.size = 14 * ui;
  title.bold = true;
  title.halign = Align::kCenter;
  flexkin::render::DrawText(cr, area.x + area.w / 2, area.y - 14 * ui, s.title, title);
}

// Each joint's total motion (deg), the two methods side by side.
void DrawMotion(cairo_t* cr, double ui, const Rect& area, const Series& a, const Series& b) {
  const int n = static_cast<int>(a.motion.size());
  const double top = std::max(a.motion.maxCoeff(), b.motion.maxCoeff()) * kDeg * 1.08;
  Axes axes(area, -0.5, n - 0.5, 0.0, top);
  axes.SetIntegerX();
  axes.Draw(cr, ui, "joint (0 = base)", "total motion sum |dθ| (deg)");
  const flexkin::render::Rgb colors[2] = {flexkin::render::kFinal, flexkin::render::kMarker};
  for (int j = 0; j < n; ++j) {
    for (int m = 0; m < 2; ++m) {
      const double v = (m == 0 ? a : b).motion[j] * kDeg;
      const double x = axes.X(j - 0.38 + 0.38 * m), w = axes.X(0.34) - axes.X(0.0);
      flexkin::render::SetColor(cr, colors[m]);
      cairo_rectangle(cr, x, axes.Y(v), w, axes.Y(0.0) - axes.Y(v));
      cairo_fill(cr);
    }
  }
  TextStyle key;
  key.size = 12 * ui;
  for (int m = 0; m < 2; ++m) {
    const double y = area.y + (12 + 18 * m) * ui;
    flexkin::render::SetColor(cr, colors[m]);
    cairo_rectangle(cr, area.right() - 150 * ui, y - 5 * ui, 12 * ui, 10 * ui);
    cairo_fill(cr);
    flexkin::render::DrawText(cr, area.right() - 132 * ui, y,
                              m == 0 ? "tractrix" : "pseudo-inverse", key);
  }
  TextStyle title;
  title.size = 14 * ui;
  title.bold = true;
  title.halign = Align::kCenter;
  flexkin::render::DrawText(cr, area.x + area.w / 2, area.y - 14 * ui, "each joint's total motion",
                            title);
}

void DrawFigure(flexkin::ImageFormat format, const std::string& path, const std::string& name,
                Series a, Series b) {
  a.angles = Unwrapped(a.angles);
  b.angles = Unwrapped(b.angles);
  Canvas canvas(format, 1500, 560);
  cairo_t* cr = canvas.cr();
  const double ui = canvas.ui();
  double lo = 1e300, hi = -1e300;
  for (const Series* s : {&a, &b}) {
    for (const JointAngles& q : s->angles) {
      lo = std::min(lo, q.angle.minCoeff() * kDeg);
      hi = std::max(hi, q.angle.maxCoeff() * kDeg);
    }
  }
  const double range = hi - lo;
  const double y_step = range > 300 ? 90 : range > 150 ? 45 : range > 60 ? 15 : 5;
  lo = y_step * std::floor(lo / y_step - 0.05);
  hi = y_step * std::ceil(hi / y_step + 0.05);
  TextStyle heading;
  heading.size = 15 * ui;
  heading.halign = Align::kCenter;
  flexkin::render::DrawText(cr, 750, 22 * ui, name, heading);
  const double top = 80 * ui, h = 560 - top - 70 * ui;
  DrawAngles(cr, ui, Rect{70 * ui, top, 390, h}, a, lo, hi, y_step);
  DrawAngles(cr, ui, Rect{70 * ui + 480, top, 390, h}, b, lo, hi, y_step);
  DrawMotion(cr, ui, Rect{70 * ui + 960, top, 400, h}, a, b);
  TextStyle note;
  note.size = 11.5 * ui;
  note.color = flexkin::render::kMuted;
  flexkin::render::DrawText(cr, 70 * ui, 560 - 14 * ui,
                            "lines: joint 0 (base, dark) to joint n-1 (end effector, yellow)",
                            note);
  flexkin::render::SaveCanvas(&canvas, path);
}

void WriteCsv(const std::string& path, const flexkin::Points& targets, const Series& a,
              const Series& b) {
  flexkin::WriteFileAtomically(path, [&](std::ostream& out) {
    const int n = static_cast<int>(a.motion.size());
    out << "step,target_x,target_y";
    for (const char* m : {"tractrix", "pinv"}) {
      for (int j = 0; j < n; ++j) out << "," << m << "_joint" << j << "_rad";
    }
    out << "\n";
    char buffer[32];
    for (size_t i = 0; i < a.angles.size(); ++i) {
      out << i;
      for (int c = 0; c < 2; ++c) {
        if (i == 0) {
          out << ",";
        } else {
          std::snprintf(buffer, sizeof buffer, ",%.9g",
                        targets(static_cast<Eigen::Index>(i) - 1, c));
          out << buffer;
        }
      }
      for (const Series* s : {&a, &b}) {
        for (int j = 0; j < n; ++j) {
          std::snprintf(buffer, sizeof buffer, ",%.17g", s->angles[i].angle[j]);
          out << buffer;
        }
      }
      out << "\n";
    }
  });
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr
        << "usage: robot_compare SCENARIO.json OUT_PREFIX (writes OUT_PREFIX.svg, .png, .csv)\n";
    return 1;
  }
  try {
    const flexkin::RobotScenario s =
        flexkin::LoadRobotScenarioFile(argv[1], flexkin::UrdfRobotScenarioOptions());
    if (s.model.dim != 2) {
      throw flexkin::InputError("/arm/dim", "robot_compare draws planar arms only (dim 2)");
    }
    const std::string prefix = argv[2];
    const flexkin::ArmTrajectory tractrix = flexkin::TrackPath(s.model, s.path, s.options);
    flexkin::peers::KdlOptions kdl_options;
    kdl_options.tolerance = s.options.tolerance;
    const flexkin::peers::KdlTrajectory pinv = flexkin::peers::TrackPathWithKdl(
        s.model, s.path, flexkin::peers::KdlSolver::kNewtonPinv, kdl_options);

    Series a{"tractrix (flexkin, fixed base)", {s.model.initial}, {}};
    for (const auto& step : tractrix.steps) a.angles.push_back(step.state.angles);
    Series b{"pseudo-inverse (KDL NR + pinv)", {s.model.initial}, {}};
    for (const auto& step : pinv.steps) b.angles.push_back(step.angles);
    a.motion = flexkin::peers::TotalJointMotion(
        s.model, s.model.initial, std::vector<JointAngles>(a.angles.begin() + 1, a.angles.end()));
    b.motion = flexkin::peers::TotalJointMotion(
        s.model, s.model.initial, std::vector<JointAngles>(b.angles.begin() + 1, b.angles.end()));

    DrawFigure(flexkin::ImageFormat::kSvg, prefix + ".svg", s.name, a, b);
    DrawFigure(flexkin::ImageFormat::kPng, prefix + ".png", s.name, a, b);
    WriteCsv(prefix + ".csv", s.path, a, b);

    std::printf("%s\n%zu steps; max end-effector error: tractrix %.2e, pseudo-inverse %.2e (m)\n",
                s.name.c_str(), s.path.rows() + 0, tractrix.max_ee_error, pinv.max_ee_error);
    std::printf("time: tractrix %.1f us/step, pseudo-inverse %.1f us/step\n",
                1e6 * tractrix.seconds / s.path.rows(), 1e6 * pinv.seconds / s.path.rows());
    std::printf("joint  total motion (deg): tractrix  pseudo-inverse\n");
    for (Eigen::Index j = 0; j < a.motion.size(); ++j) {
      std::printf("%5ld  %24.2f  %14.2f\n", static_cast<long>(j), a.motion[j] * kDeg,
                  b.motion[j] * kDeg);
    }
    std::printf("sum    %24.2f  %14.2f\nwrote %s.svg, %s.png, %s.csv\n", a.motion.sum() * kDeg,
                b.motion.sum() * kDeg, prefix.c_str(), prefix.c_str(), prefix.c_str());
    return tractrix.unreached == 0 && pinv.unreached == 0 ? 0 : 3;
  } catch (const std::exception& e) {
    std::cerr << "robot_compare: " << e.what() << "\n";
    return 1;
  }
}
