#pragma once
// Robot trees (docs/trees.md, "Robot trees"): fixed-base robots whose joints branch, such as two
// arms on a torso or several fingers on a palm, each joint revolute about a given axis. Several
// tool links are driven at once, each to a target point or turned to look at one, and the
// redundancy is resolved as for serial arms (docs/robots.md, "Revolute joints about given axes"):
// every Gauss-Newton step is the smallest joint motion, in a weighted norm that favours the joints
// near the tools, that cancels the misses to first order, with the joint limits as an active set.
// The URDF reader is RobotTreeFromUrdf (flexkin/urdf.h); this header needs only Eigen.
//
//   RobotTree robot = RobotTreeFromUrdfFile("two_arms.urdf", "torso", {{"left_hand"},
//                                                                     {"right_hand"}});
//   RobotTreeSolver solver(robot);
//   Eigen::VectorXd q = robot.initial;
//   RobotTreeSolve s = solver.Solve(q, goals);   // goals: a row per tool (k by 3)
//
// The robot is drawn, stored and animated as a tree of points (flexkin/tree.h): the base, the
// joints' origins (joints on one point share it) and the tools (RobotTreeLayout).

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"

namespace flexkin {

struct RobotTree {
  // The joints, each after its parent, at the zero pose in the base link's frame.
  std::vector<std::string> joint_names;
  std::vector<int> joint_parents;  // the joint above each (-1: on the base); parent < joint
  Eigen::Matrix<double, Eigen::Dynamic, 3> origins;  // a point of each joint's axis
  Eigen::Matrix<double, Eigen::Dynamic, 3> axes;     // unit
  Eigen::VectorXd joint_min, joint_max;  // rad (length for sliding joints); -inf, inf: unlimited
  Eigen::VectorXd initial;               // the start, within the limits
  // Per joint: 1 where it slides along its axis (a prismatic joint: its value is a displacement
  // in the length unit, and the origin moves with the joint), 0 where it turns about it. Empty:
  // every joint turns.
  std::vector<char> prismatic;
  Eigen::Vector3d base = Eigen::Vector3d::Zero();  // the base link's origin
  // The tools, one per target: a point of a link, and the axis of its frame that looks.
  struct Tool {
    std::string link;                                     // the link's name
    int joint = -1;                                       // the last joint above it
    Eigen::Vector3d point = Eigen::Vector3d::Zero();      // at the zero pose
    Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();  // the link's axes at the zero pose
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();      // the looking axis in the link's frame
  };
  std::vector<Tool> tools;

  int joints() const { return static_cast<int>(joint_parents.size()); }
  // Every problem (empty if valid), each naming its member ("joint_parents[3]", "tools[1].joint",
  // "initial[2]"): sizes, parents before their joints, unit axes, finite numbers, limits ordered
  // and holding the start, every tool below at least one joint.
  Problems Validate() const;
};

// The robot as a tree of points (flexkin/tree.h): point 0 the base, then a point per joint
// origin that is not on its parent's point (a sliding joint's always has its own), then a point
// per tool not on its joint's point. The distances between points joined by a link are fixed by
// the robot's rigid links, so the tree's links keep their lengths as the joints turn; only the
// link into a sliding joint's origin (which moves with the joint) changes its length as that
// joint slides, and may be of length 0.
struct RobotTreeLayout {
  std::vector<int> parents;      // of the points (parents[0] = -1)
  std::vector<char> sliding;     // per point: 1 where the link into it changes length
  std::vector<int> joint_point;  // the point of each joint's origin
  std::vector<int> tool_point;   // the point of each tool
  // Each joint's distance along the tree to the nearest tool below it (length; 0 where none).
  std::vector<double> tool_distance;
  double longest_link = 0.0;
  double mean_link = 0.0;  // the links' mean length
};
RobotTreeLayout MakeRobotTreeLayout(const RobotTree& robot);

// The points of the layout (rows, 3 columns) with the joints at `angles`.
Points RobotTreePoints(const RobotTree& robot, const RobotTreeLayout& layout,
                       const Eigen::VectorXd& angles);

// The tools' points (k by 3) and looking axes (k by 3, unit, in the world) at `angles`.
void RobotTreeTools(const RobotTree& robot, const Eigen::VectorXd& angles, Points* points,
                    Points* axes);

// A tool asked of a URDF robot tree (RobotTreeFromUrdf, flexkin/urdf.h; a tree scenario's
// "targets"): a point of a link's frame, and the axis of that frame that looks.
struct UrdfTool {
  std::string link;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
};

struct RobotTreeOptions {
  double tolerance = 1e-10;        // position miss, in longest links of the layout
  double angle_tolerance = 1e-10;  // rad, looking goals
  int max_iterations = 100;        // Gauss-Newton iterations a solve
  // Per tool: a looking goal (the tool's axis turned toward its goal point) rather than a
  // position target. Empty: every tool has a position target.
  std::vector<char> looks;
  // Per tool: the target's weight (> 0; empty: all 1): how much of a miss that cannot be
  // cancelled falls on the other targets.
  std::vector<double> weights;
  Problems Validate(const RobotTree& robot) const;
};

struct RobotTreeSolve {
  Eigen::VectorXd angles;       // where the solve ended, within the limits
  double residual = 0.0;        // the largest position miss (length)
  double angle_residual = 0.0;  // the largest looking miss (rad)
  int iterations = 0;
  bool converged = false;  // both within their tolerances
  bool limited = false;    // a joint ended at one of its limits
};

// A robot and options prepared for many solves (the weights, the joints above each tool, the
// storage of the iterations). Holds a reference to the robot, which must outlive it. Used by one
// thread at a time. Throws InputError for an invalid robot or options.
class RobotTreeSolver {
 public:
  explicit RobotTreeSolver(const RobotTree& robot, RobotTreeOptions options = {});
  ~RobotTreeSolver();
  RobotTreeSolver(RobotTreeSolver&&) noexcept;
  RobotTreeSolver(const RobotTreeSolver&) = delete;
  RobotTreeSolver& operator=(const RobotTreeSolver&) = delete;
  const RobotTreeLayout& layout() const { return layout_; }
  // The inverse weights of the joint-motion norm: joint j's 1 / (d_j / mean link)^2, d_j its
  // distance to the nearest tool below it (at least half a mean link); a sliding joint's (its
  // motion moves the tools as far as it slides) the mean link squared.
  const Eigen::VectorXd& inverse_weights() const { return winv_; }

  // From `from` (within the limits) toward `goals` (a row per tool: the target point, or the
  // point looked at): Gauss-Newton steps, each the smallest weighted joint motion that cancels
  // the weighted misses to first order (a looking goal's miss is its angle times the mean link),
  // joints that would leave their limits put on them and held; a backtracking line search, and
  // Levenberg-Marquardt damping where full steps fail. Where the goals cannot be met, ends once
  // ten iterations gain less than 1e-4 of the squared misses, at the configuration found. A
  // step turns no joint by more than half a radian and slides none by more than half a mean
  // link (a longer one is scaled down whole). Throws
  // InputError for angles or goals of the wrong shape or not finite.
  RobotTreeSolve Solve(const Eigen::VectorXd& from, const Points& goals) const;

 private:
  const RobotTree& robot_;
  RobotTreeOptions options_;
  RobotTreeLayout layout_;
  Eigen::VectorXd winv_;
  std::vector<std::vector<int>> above_;  // per tool: the joints above it
  std::vector<int> first_row_;           // per tool: its first row of the misses
  int rows_ = 0;
  struct Workspace;  // the storage of the iterations, kept from one solve to the next
  std::unique_ptr<Workspace> work_;
};

}  // namespace flexkin
