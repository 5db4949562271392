#pragma once
// Tree scenario files (docs/trees.md, "Scenario files"; docs/schema/tree.schema.json): a tree,
// the points driven along their paths, the fixed points, and the method; read through the front
// door (flexkin/any_scenario.h) as the scenario kind "tree", run, and written as a tree result
// (.npz or .json: the frames and the parents).
//
//   {"format": "flexkin-tree",
//    "tree": {"points": [[0, 0, 0], [0, 0, 1], ...], "parents": [-1, 0, 1, ...]},
//    "targets": [{"point": 7, "path": [[...], ...]}, {"point": 12, "path": [[...], ...]}],
//    "fixed": [0], "method": "tractrix"}

#include <memory>
#include <string>
#include <vector>

#include "flexkin/overall.h"
#include "flexkin/robot_tree.h"
#include "flexkin/tree.h"
#include "flexkin/tree_overall.h"

namespace flexkin {

struct TreeScenario {
  std::string name;                   // "name", "" if none
  Tree tree;                          // "tree"
  std::vector<int> targets;           // "targets"[k]."point"
  std::vector<Points> paths;          // "targets"[k]."path" (or "look_at"): a row per frame
  std::vector<char> looks;            // per target: "look_at" given, a pointing goal (tree.h)
  std::vector<double> weights;        // "targets"[k]."weight" (1 if none)
  std::vector<int> fixed;             // "fixed"
  Method method = Method::kTractrix;  // "method"
  int substeps = 1;                   // "substeps": one target and nothing fixed only
  ReachOptions reach;                 // "branch_rule", "tolerance", "max_passes"
  bool finish = true;                 // "finish": FinishTreeReach after passes that stall
  TreeOverallOptions overall;         // "overall": the metric's weights (method "overall")
  // A URDF robot tree ("robot", docs/trees.md "Robot trees") rather than a tree of points: `tree`
  // is its layout (RobotTreeLayout) at the start, targets[k] the point of its tool k (the link of
  // "targets"[k]), `fixed` the base; its joints are solved by RobotTreeSolver with
  // reach.tolerance and reach.max_passes (iterations a frame). Null: a tree of points.
  std::shared_ptr<const RobotTree> robot;
  // A robot tree's points whose link into them slides (its prismatic joints,
  // RobotTreeLayout::sliding); empty for a tree of points.
  std::vector<int> sliding;

  // One driven point and nothing fixed: moved by MoveTreePoint (any rule of trees); otherwise
  // by the passes (tractrix, ftl) or, with method "overall", by StepTreeOverall.
  bool driven_at_one_point() const {
    return !robot && targets.size() == 1 && fixed.empty() && (looks.empty() || !looks[0]);
  }
  int frames() const { return paths.empty() ? 0 : static_cast<int>(paths[0].rows()); }
};

// Every frame of a tree run: the start and one per row of the paths, with each frame's report.
struct TreeRunResult {
  std::vector<Points> frames;
  std::vector<int> passes;        // per frame after the start (0 for a tree driven at one point)
  std::vector<double> residual;   // of the longest link (0 for a tree driven at one point)
  std::vector<char> reached;      // (1 for a tree driven at one point)
  std::vector<char> converged;    // the overall step's (method "overall"; else 1)
  std::vector<char> finished;     // passes that stalled, completed by FinishTreeReach
  double max_length_error = 0.0;  // largest relative link-length error over the frames
  std::vector<Eigen::VectorXd> angles;  // a robot tree's joint angles, every frame

  int failures() const;  // frames not reached or not converged
  std::string BriefReport() const;
};

// "tree: 13 points (12 links, 3D), 2 targets, 1 fixed, tractrix passes (centroid), 120 frames".
std::string TreeSummary(const TreeScenario& scenario);

// Runs every frame, each from the last. Throws InputError where the library refuses the scenario
// (a scenario read without problems is not refused). `progress(done, total)`, if set, is called
// after every frame and may throw to stop the run.
TreeRunResult RunTree(const TreeScenario& scenario,
                      const std::function<void(int64_t, int64_t)>& progress = {});

// Writes the result to `path`, whole or not at all (an earlier file stays if writing fails): .npz
// (arrays frames (F, n+1, dim), parents (n+1), passes, residual, reached, converged (F-1), and
// tree.json: the format, name and method) or .json (docs/trees.md, "Results"). Throws InputError
// for another extension (field "output") and std::system_error if it cannot be written.
void WriteTreeResult(const std::string& path, const TreeScenario& scenario,
                     const TreeRunResult& result);

// Whether a tree result at `path` is .npz (true) or .json (false); throws InputError (field
// "output") for another extension. WriteTreeResult and RunScenarioToFiles check with it before
// anything runs or is written.
bool CheckTreeResultPath(const std::string& path);

// A tree result read back (ReadTreeResultFile): what WriteTreeResult wrote, as far as the
// pictures, animations and glTF need it.
struct TreeResultFile {
  std::string name;                   // the scenario's name, "" if none
  Method method = Method::kTractrix;  // the method of the run
  int dim = 0;                        // 2 or 3
  std::vector<int> parents;           // n+1 entries: a valid tree (ValidateTree)
  std::vector<int> targets;           // the driven points, in the scenario's order
  std::vector<int> fixed;             // the fixed points
  std::vector<Points> frames;         // F >= 1 frames, each (n+1) by dim, finite
  std::vector<char> reached;          // F - 1: each frame after the start reached and converged
  std::vector<char> looks;            // per target: a pointing goal (empty: none are)
  // F - 1 frames (empty in files without "goals"): row k of frame f's the goal of target k at
  // frame f + 1, the position it was driven to or the point it looked at.
  std::vector<Points> goals;
  bool robot = false;                   // a robot tree's result ("method": "newton")
  std::vector<std::string> joints;      // a robot tree's joint names
  std::vector<Eigen::VectorXd> angles;  // a robot tree's joint angles, every frame (or none)
  // The points whose link into them slides (a robot tree's prismatic joints: its length changes,
  // and may be 0); empty in files without "sliding".
  std::vector<int> sliding;
  // Per joint of a robot tree: 1 where it slides (its "angles" are displacements, in the length
  // unit); empty in files without "prismatic" (every joint turns).
  std::vector<char> prismatic;
};

// Reads a tree result (.npz or .json, told apart by content) and checks it: the format, the
// shapes (every frame (n+1) by dim, n+1 = the number of parents), finite coordinates, the parents
// a tree whose first frame has no link of length 0, targets and fixed points among its points.
// Throws std::system_error if the file cannot be read, InputError naming the member or JSON
// pointer ("tree.json/parents/4", "frames.npy", "/frames/3/7/1") otherwise.
TreeResultFile ReadTreeResultFile(const std::string& path);

// The same checks of a tree result made in memory, each problem by its member ("frames[3][7][1]",
// "parents[4]", "targets[0]", "reached"): what the pictures, animations and glTF of trees check.
Problems ValidateTreeResult(const TreeResultFile& tree);

// Whether the file at `path` is a tree result (.npz with tree.json and frames.npy, or JSON whose
// "format" is "flexkin-tree-result"); false for anything else, unreadable files included.
bool IsTreeResultFile(const std::string& path);

}  // namespace flexkin
