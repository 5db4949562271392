// Robot trees (include/flexkin/robot_tree.h, docs/trees.md "Robot trees"): the layout of points,
// forward kinematics as a product of exponentials, and the joint-space Gauss-Newton solve of
// several tools with the joint limits as an active set.
#include "flexkin/robot_tree.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace flexkin {
namespace {

std::string Member(const char* name, size_t i) {
  return std::string(name) + "[" + std::to_string(i) + "]";
}

bool Slides(const RobotTree& robot, int j) {
  return !robot.prismatic.empty() && robot.prismatic[j];
}

// The joints' frames at `q`: joint j moves the points of its subtree by x -> rot[j] x + shift[j]
// (x at the zero pose), and its origin and axis are at origin[j] and axis[j] in the world. A
// turning joint's origin is on its axis, where its subtree turns about; a sliding joint's moves
// with it (origin[j] = rot[j] o0 + shift[j] for both).
struct RobotFrames {
  std::vector<Eigen::Matrix3d> rot;
  std::vector<Eigen::Vector3d> shift, origin, axis;

  void Compute(const RobotTree& robot, const Eigen::VectorXd& q) {
    const int n = robot.joints();
    rot.resize(n);
    shift.resize(n);
    origin.resize(n);
    axis.resize(n);
    for (int j = 0; j < n; ++j) {
      const int p = robot.joint_parents[j];
      const Eigen::Vector3d o0 = robot.origins.row(j).transpose();
      const Eigen::Vector3d a0 = robot.axes.row(j).transpose();
      if (Slides(robot, j)) {
        axis[j] = p < 0 ? a0 : Eigen::Vector3d(rot[p] * a0);
        rot[j] = p < 0 ? Eigen::Matrix3d::Identity() : rot[p];
        shift[j] = (p < 0 ? Eigen::Vector3d::Zero() : shift[p]) + q[j] * axis[j];
        origin[j] = rot[j] * o0 + shift[j];
        continue;
      }
      if (p < 0) {
        origin[j] = o0;
        axis[j] = a0;
        rot[j] = Eigen::AngleAxisd(q[j], a0).toRotationMatrix();
      } else {
        origin[j] = rot[p] * o0 + shift[p];
        axis[j] = rot[p] * a0;
        rot[j] = rot[p] * Eigen::AngleAxisd(q[j], a0).toRotationMatrix();
      }
      shift[j] = origin[j] - rot[j] * o0;
    }
  }
  Eigen::Vector3d Tool(const RobotTree::Tool& tool) const {
    return rot[tool.joint] * tool.point + shift[tool.joint];
  }
  Eigen::Vector3d ToolAxis(const RobotTree::Tool& tool) const {
    return (rot[tool.joint] * (tool.frame * tool.axis)).normalized();
  }
};

double Extent(const RobotTree& robot) {
  double extent = robot.base.norm();
  for (int j = 0; j < robot.joints(); ++j) extent = std::max(extent, robot.origins.row(j).norm());
  for (const RobotTree::Tool& t : robot.tools) extent = std::max(extent, t.point.norm());
  return extent;
}

}  // namespace

struct RobotTreeSolver::Workspace {
  RobotFrames frames, trial_frames;
  Eigen::VectorXd e, trial_e, dq, trial, rhs, y;
  Eigen::MatrixXd jac, trial_jac, weighted, normal;
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
  std::vector<char> held;
};

RobotTreeSolver::~RobotTreeSolver() = default;
RobotTreeSolver::RobotTreeSolver(RobotTreeSolver&&) noexcept = default;

namespace {

// The largest misses of a configuration: positions (length) and looking goals (rad).
struct RobotMisses {
  double position = 0.0, angle = 0.0;
};

}  // namespace

Problems RobotTree::Validate() const {
  Problems out;
  const size_t n = joint_parents.size();
  if (n == 0) out.push_back(Problem("joint_parents", "is empty; expected at least one joint"));
  auto size = [&](const char* name, size_t have) {
    if (have != n) {
      out.push_back(Problem(name, "has " + std::to_string(have) +
                                      " entries; expected one per joint (" + std::to_string(n) +
                                      ")"));
    }
  };
  size("joint_names", joint_names.size());
  size("origins", static_cast<size_t>(origins.rows()));
  size("axes", static_cast<size_t>(axes.rows()));
  size("joint_min", static_cast<size_t>(joint_min.size()));
  size("joint_max", static_cast<size_t>(joint_max.size()));
  size("initial", static_cast<size_t>(initial.size()));
  if (!prismatic.empty()) size("prismatic", prismatic.size());
  if (!out.empty()) return out;
  if (!base.allFinite()) out.push_back(Problem("base", "is not finite; expected a point"));
  for (size_t j = 0; j < n; ++j) {
    const int p = joint_parents[j];
    if (p < -1 || p >= static_cast<int>(j)) {
      out.push_back(Problem::Invalid(Member("joint_parents", j), std::to_string(p),
                                     "-1 (on the base) or a joint before it (0.." +
                                         std::to_string(static_cast<int>(j) - 1) + ")"));
    }
    if (!origins.row(j).allFinite()) {
      out.push_back(Problem(Member("origins", j), "is not finite; expected a point"));
    }
    if (!(std::abs(axes.row(j).norm() - 1.0) <= 1e-9)) {
      out.push_back(Problem::Invalid(Member("axes", j), FormatNumber(axes.row(j).norm()),
                                     "a unit vector (the joint's axis)"));
    }
    if (std::isnan(joint_min[j]) || std::isnan(joint_max[j]) || !(joint_min[j] <= joint_max[j])) {
      out.push_back(Problem::Invalid(Member("joint_min", j), FormatNumber(joint_min[j]),
                                     "a lower limit <= the upper limit " +
                                         FormatNumber(joint_max[j]) +
                                         (Slides(*this, j) ? " (length)" : " (rad)")));
    } else if (!std::isfinite(initial[j]) || initial[j] < joint_min[j] ||
               initial[j] > joint_max[j]) {
      out.push_back(Problem::Invalid(Member("initial", j), FormatNumber(initial[j]),
                                     std::string(Slides(*this, j) ? "a displacement" : "an angle") +
                                         " within [" + FormatNumber(joint_min[j]) + ", " +
                                         FormatNumber(joint_max[j]) + "]"));
    }
  }
  for (size_t k = 0; k < tools.size(); ++k) {
    const Tool& t = tools[k];
    const std::string field = Member("tools", k);
    if (t.joint < 0 || t.joint >= static_cast<int>(n)) {
      out.push_back(Problem::Invalid(field + ".joint", std::to_string(t.joint),
                                     "a joint index (a tool below no joint cannot move)"));
    }
    if (!t.point.allFinite() || !t.frame.allFinite()) {
      out.push_back(Problem(field + ".point", "is not finite; expected a point"));
    }
    if (!(t.axis.norm() > 0.0) || !t.axis.allFinite()) {
      out.push_back(Problem::Invalid(field + ".axis", FormatNumber(t.axis.norm()),
                                     "a non-zero direction in the link's frame"));
    }
  }
  return out;
}

RobotTreeLayout MakeRobotTreeLayout(const RobotTree& robot) {
  ThrowIfAny(robot.Validate());
  RobotTreeLayout layout;
  const double eps = 1e-9 * (1.0 + Extent(robot));
  std::vector<Eigen::Vector3d> at{robot.base};
  std::vector<double> depth{0.0};  // the length along the tree from the base
  layout.parents = {-1};
  layout.sliding = {0};
  auto place = [&](int parent, const Eigen::Vector3d& x, bool slides = false) {
    const double length = (x - at[parent]).norm();
    if (!(length > eps) && !slides) return parent;
    layout.parents.push_back(parent);
    layout.sliding.push_back(slides ? 1 : 0);
    at.push_back(x);
    depth.push_back(depth[parent] + length);
    layout.longest_link = std::max(layout.longest_link, length);
    layout.mean_link += length;  // the total, divided below
    return static_cast<int>(at.size()) - 1;
  };
  const int n = robot.joints();
  for (int j = 0; j < n; ++j) {
    const int p = robot.joint_parents[j];
    layout.joint_point.push_back(place(p < 0 ? 0 : layout.joint_point[p],
                                       robot.origins.row(j).transpose(), Slides(robot, j)));
  }
  for (const RobotTree::Tool& t : robot.tools) {
    layout.tool_point.push_back(place(layout.joint_point[t.joint], t.point));
  }
  if (layout.parents.size() < 2) {
    throw InputError("origins",
                     "every joint and tool is on the base point; expected a robot of "
                     "positive length");
  }
  layout.mean_link /= static_cast<double>(layout.parents.size() - 1);
  layout.tool_distance.assign(n, 0.0);
  std::vector<char> has(n, 0);
  for (size_t k = 0; k < robot.tools.size(); ++k) {
    for (int j = robot.tools[k].joint; j >= 0; j = robot.joint_parents[j]) {
      const double d = depth[layout.tool_point[k]] - depth[layout.joint_point[j]];
      layout.tool_distance[j] = has[j] ? std::min(layout.tool_distance[j], d) : d;
      has[j] = 1;
    }
  }
  return layout;
}

Points RobotTreePoints(const RobotTree& robot, const RobotTreeLayout& layout,
                       const Eigen::VectorXd& angles) {
  RobotFrames f;
  f.Compute(robot, angles);
  Points points(layout.parents.size(), 3);
  points.row(0) = robot.base.transpose();
  for (int j = 0; j < robot.joints(); ++j) {
    const int p = robot.joint_parents[j];
    const int parent_point = p < 0 ? 0 : layout.joint_point[p];
    if (layout.joint_point[j] != parent_point) points.row(layout.joint_point[j]) = f.origin[j];
  }
  for (size_t k = 0; k < robot.tools.size(); ++k) {
    const RobotTree::Tool& t = robot.tools[k];
    if (layout.tool_point[k] != layout.joint_point[t.joint]) {
      points.row(layout.tool_point[k]) = f.Tool(t).transpose();
    }
  }
  return points;
}

void RobotTreeTools(const RobotTree& robot, const Eigen::VectorXd& angles, Points* points,
                    Points* axes) {
  RobotFrames f;
  f.Compute(robot, angles);
  const int k = static_cast<int>(robot.tools.size());
  points->resize(k, 3);
  axes->resize(k, 3);
  for (int i = 0; i < k; ++i) {
    points->row(i) = f.Tool(robot.tools[i]).transpose();
    axes->row(i) = f.ToolAxis(robot.tools[i]).transpose();
  }
}

Problems RobotTreeOptions::Validate(const RobotTree& robot) const {
  Problems out;
  const size_t k = robot.tools.size();
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    out.push_back(Problem::Invalid("tolerance", FormatNumber(tolerance), "a number > 0"));
  }
  if (!(angle_tolerance > 0.0) || !std::isfinite(angle_tolerance)) {
    out.push_back(
        Problem::Invalid("angle_tolerance", FormatNumber(angle_tolerance), "a number > 0 (rad)"));
  }
  if (max_iterations < 1) {
    out.push_back(
        Problem::Invalid("max_iterations", std::to_string(max_iterations), "an integer >= 1"));
  }
  if (!looks.empty() && looks.size() != k) {
    out.push_back(Problem("looks", "has " + std::to_string(looks.size()) +
                                       " entries; expected none or one per tool (" +
                                       std::to_string(k) + ")"));
  }
  if (!weights.empty() && weights.size() != k) {
    out.push_back(Problem("weights", "has " + std::to_string(weights.size()) +
                                         " entries; expected none or one per tool (" +
                                         std::to_string(k) + ")"));
  }
  for (size_t i = 0; i < weights.size(); ++i) {
    if (!(weights[i] > 0.0) || !std::isfinite(weights[i])) {
      out.push_back(
          Problem::Invalid(Member("weights", i), FormatNumber(weights[i]), "a number > 0"));
    }
  }
  if (k == 0) out.push_back(Problem("tools", "is empty; expected at least one tool to drive"));
  return out;
}

RobotTreeSolver::RobotTreeSolver(const RobotTree& robot, RobotTreeOptions options)
    : robot_(robot), options_(std::move(options)) {
  ThrowIfAny(options_.Validate(robot));
  layout_ = MakeRobotTreeLayout(robot);  // validates the robot
  const int n = robot.joints();
  const size_t k = robot.tools.size();
  if (options_.looks.empty()) options_.looks.assign(k, 0);
  if (options_.weights.empty()) options_.weights.assign(k, 1.0);
  winv_.resize(n);
  for (int j = 0; j < n; ++j) {
    const double d =
        std::max(layout_.tool_distance[j], 0.5 * layout_.mean_link) / layout_.mean_link;
    winv_[j] = Slides(robot, j) ? layout_.mean_link * layout_.mean_link : 1.0 / (d * d);
  }
  above_.resize(k);
  for (size_t i = 0; i < k; ++i) {
    for (int j = robot.tools[i].joint; j >= 0; j = robot.joint_parents[j]) above_[i].push_back(j);
    first_row_.push_back(rows_);
    rows_ += options_.looks[i] ? 2 : 3;
  }
  work_ = std::make_unique<Workspace>();
  Workspace& w = *work_;
  for (Eigen::VectorXd* v : {&w.e, &w.trial_e, &w.rhs, &w.y}) v->setZero(rows_);
  for (Eigen::VectorXd* v : {&w.dq, &w.trial}) v->setZero(n);
  w.jac.setZero(rows_, n);
  w.trial_jac.setZero(rows_, n);
  w.weighted.setZero(n, rows_);
  w.normal.setZero(rows_, rows_);
  w.held.assign(n, 0);
}

RobotTreeSolve RobotTreeSolver::Solve(const Eigen::VectorXd& from, const Points& goals) const {
  const RobotTree& robot = robot_;
  const int n = robot.joints();
  const int k = static_cast<int>(robot.tools.size());
  if (from.size() != n) {
    throw InputError("from", "has " + std::to_string(from.size()) + " angles; expected " +
                                 std::to_string(n) + " (one per joint)");
  }
  for (int j = 0; j < n; ++j) {
    if (!std::isfinite(from[j])) {
      throw InputError(Member("from", static_cast<size_t>(j)),
                       FormatNumber(from[j]) + " is not valid; expected a finite angle (rad)");
    }
  }
  if (goals.rows() != k || goals.cols() != 3) {
    throw InputError("goals", "is " + std::to_string(goals.rows()) + " by " +
                                  std::to_string(goals.cols()) + "; expected " + std::to_string(k) +
                                  " by 3 (a point per tool)");
  }
  for (int i = 0; i < k; ++i) {
    if (!goals.row(i).allFinite()) {
      throw InputError(Member("goals", static_cast<size_t>(i)), "is not finite; expected a point");
    }
  }
  const int rows = rows_;
  const double length_tol = options_.tolerance * layout_.longest_link;
  Workspace& w = *work_;
  RobotTreeSolve out;
  out.angles = from.cwiseMax(robot.joint_min).cwiseMin(robot.joint_max);

  // The weighted misses at q and their Jacobian (rows by n), and the largest misses.
  auto evaluate = [&](const Eigen::VectorXd& q, RobotFrames* frames, Eigen::VectorXd* err,
                      Eigen::MatrixXd* jac) {
    frames->Compute(robot, q);
    RobotMisses m;
    jac->setZero();
    for (int i = 0; i < k; ++i) {
      const RobotTree::Tool& tool = robot.tools[i];
      const double s = std::sqrt(options_.weights[i]);
      const Eigen::Vector3d x = frames->Tool(tool);
      const int r0 = first_row_[i];
      if (!options_.looks[i]) {
        const Eigen::Vector3d miss = goals.row(i).transpose() - x;
        m.position = std::max(m.position, miss.norm());
        err->segment<3>(r0) = s * miss;
        for (int j : above_[i]) {
          jac->block<3, 1>(r0, j) =
              Slides(robot, j) ? Eigen::Vector3d(s * frames->axis[j])
                               : Eigen::Vector3d(s * frames->axis[j].cross(x - frames->origin[j]));
        }
        continue;
      }
      // Looking: the rotation taking the tool's axis d to the direction g of the goal point.
      const Eigen::Vector3d to = goals.row(i).transpose() - x;
      const double r = to.norm();
      if (!(r > 1e-12 * layout_.longest_link)) {  // on the point looked at: nothing to turn
        err->segment<2>(r0).setZero();
        continue;
      }
      const Eigen::Vector3d g = to / r;
      const Eigen::Vector3d d = frames->ToolAxis(tool);
      Eigen::Vector3d turn = d.cross(g);
      const double sine = turn.norm(), angle = std::atan2(sine, d.dot(g));
      turn = sine > 0.0 ? Eigen::Vector3d(turn * (angle / sine))
                        : (d.dot(g) < 0.0 ? Eigen::Vector3d(angle * d.unitOrthogonal())
                                          : Eigen::Vector3d::Zero());
      m.angle = std::max(m.angle, angle);
      const Eigen::Vector3d u = g.unitOrthogonal(), v = g.cross(u);
      const double scale = s * layout_.mean_link;
      (*err)[r0] = scale * u.dot(turn);
      (*err)[r0 + 1] = scale * v.dot(turn);
      for (int j : above_[i]) {
        const Eigen::Vector3d a = frames->axis[j];
        // The tool's axis turns at a per unit of q_j; the direction to the goal turns at
        // -(g x xdot) / r as the tool point moves at xdot. A sliding joint turns nothing and
        // moves the tool point at a.
        const Eigen::Vector3d c =
            Slides(robot, j) ? Eigen::Vector3d(g.cross(a) / r)
                             : Eigen::Vector3d(a + g.cross(a.cross(x - frames->origin[j])) / r);
        (*jac)(r0, j) = scale * u.dot(c);
        (*jac)(r0 + 1, j) = scale * v.dot(c);
      }
    }
    return m;
  };
  auto done = [&](const RobotMisses& m) {
    return m.position <= length_tol && m.angle <= options_.angle_tolerance;
  };

  RobotMisses misses = evaluate(out.angles, &w.frames, &w.e, &w.jac);
  double merit = w.e.squaredNorm();
  double damping = 0.0;
  // Goals out of reach: the steps creep along the limits toward the nearest configuration; ten
  // iterations that gain less than 1e-4 of the squared misses end the solve where it is.
  double ten_ago = merit;
  int iteration = 0;
  for (; iteration < options_.max_iterations && !done(misses); ++iteration) {
    if (iteration % 10 == 0 && iteration > 0) {
      if (ten_ago - merit <= 1e-4 * ten_ago) break;
      ten_ago = merit;
    }
    // The smallest weighted step that cancels the misses to first order; joints that it would
    // carry past a limit are put on the limit and held, and the others solved again.
    std::fill(w.held.begin(), w.held.end(), 0);
    for (int j = 0; j < n; ++j) w.weighted.row(j) = winv_[j] * w.jac.col(j).transpose();
    for (int pass = 0; pass <= n; ++pass) {
      w.rhs = w.e;
      for (int j = 0; j < n; ++j) {
        if (w.held[j]) w.rhs.noalias() -= w.jac.col(j) * w.dq[j];
      }
      w.normal.noalias() = w.jac.lazyProduct(w.weighted);
      const double trace = w.normal.trace();
      w.normal.diagonal().array() += (damping + 1e-15) * trace / rows;
      w.ldlt.compute(w.normal);
      w.y = w.ldlt.solve(w.rhs);
      bool more = false;
      for (int j = 0; j < n; ++j) {
        if (w.held[j]) continue;
        w.dq[j] = w.weighted.row(j).dot(w.y);
        const double to = out.angles[j] + w.dq[j];
        if (to > robot.joint_max[j] || to < robot.joint_min[j]) {
          w.dq[j] =
              (to > robot.joint_max[j] ? robot.joint_max[j] : robot.joint_min[j]) - out.angles[j];
          w.held[j] = 1;
          w.weighted.row(j).setZero();
          more = true;
        }
      }
      if (!more) break;
    }
    // At most half a radian a joint (half a mean link a sliding joint) per iteration: far goals
    // are approached in several.
    double largest = 0.0;
    for (int j = 0; j < n; ++j) {
      largest = std::max(
          largest, Slides(robot, j) ? std::abs(w.dq[j]) / layout_.mean_link : std::abs(w.dq[j]));
    }
    if (largest > 0.5) w.dq *= 0.5 / largest;
    bool accepted = false;
    RobotMisses trial_misses;
    for (double alpha = 1.0; alpha > 1e-6; alpha *= 0.5) {
      w.trial = (out.angles + alpha * w.dq).cwiseMax(robot.joint_min).cwiseMin(robot.joint_max);
      trial_misses = evaluate(w.trial, &w.trial_frames, &w.trial_e, &w.trial_jac);
      if (w.trial_e.squaredNorm() < merit) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      // No descent along the step: damp it toward the gradient, or stop where that is spent.
      if (damping > 1e6) break;
      damping = damping == 0.0 ? 1e-6 : damping * 10.0;
      continue;
    }
    damping = damping > 1e-6 ? damping * 0.1 : 0.0;
    out.angles.swap(w.trial);
    w.e.swap(w.trial_e);
    w.jac.swap(w.trial_jac);
    std::swap(w.frames, w.trial_frames);
    misses = trial_misses;
    merit = w.e.squaredNorm();
  }
  out.iterations = iteration;
  out.residual = misses.position;
  out.angle_residual = misses.angle;
  out.converged = done(misses);
  for (int j = 0; j < n; ++j) {
    out.limited =
        out.limited || out.angles[j] == robot.joint_min[j] || out.angles[j] == robot.joint_max[j];
  }
  return out;
}

}  // namespace flexkin
