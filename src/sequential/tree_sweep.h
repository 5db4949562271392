#pragma once
// The links of a tree driven at one point as the sweeps read them (flexkin/tree.h, tree.cc), and
// the SIMD engines' entry points (tree_wavefront.h, compiled in tree_isa.cc per instruction set).

#include <cstdint>
#include <vector>

#include "flexkin/propagate.h"
#include "flexkin/tree.h"

namespace flexkin::internal {

struct TreeLinks {
  int driven = 0;
  int num_points = 0;
  int num_links = 0;
  const int* lead = nullptr;    // link j joins point lead[j] (leading) ...
  const int* tail = nullptr;    // ... to point tail[j]
  const int* source = nullptr;  // the link whose trailing end is lead[j]; -1: the driven point
  const double* lengths = nullptr;
  const double* inv_lengths = nullptr;
};

// The whole-tree rules, driven at tree.driven through `heads` (num_sweeps by dim): min_rotation
// (every point moves by the driven point's shift, as SweepsMinRotation), min_joint_angle (each
// link from the driven point by the tractrix step, the subtree behind it turned and moved rigidly
// with it, as SweepsMinJointAngle).
void TreeSweepsMinRotation(int dim, const double* heads, int64_t num_sweeps, const TreeLinks& tree,
                           double* points);
void TreeSweepsMinJointAngle(int dim, const double* heads, int64_t num_sweeps,
                             const TreeLinks& tree, double* points);

// The first sweeps of `num_sweeps` (a multiple of the SIMD width) of a tree rule on the
// instruction set's wavefront; returns how many were done. The driven point visits `heads`
// (num_sweeps by dim, row-major); `points` is (num points) by dim, row-major.
using TreeWavefrontFn = int64_t (*)(Method, int, const double*, int64_t, const TreeLinks&, double*);
int64_t TreeWavefrontAvx2(Method method, int dim, const double* heads, int64_t num_sweeps,
                          const TreeLinks& tree, double* points);
int64_t TreeWavefrontAvx512(Method method, int dim, const double* heads, int64_t num_sweeps,
                            const TreeLinks& tree, double* points);

// Every tree wavefront this CPU can run, whatever FLEXKIN_SIMD says (for tests), and the one
// MoveTreePoint takes (the widest FLEXKIN_SIMD allows; null: none).
struct TreeWavefrontEngine {
  const char* name;
  TreeWavefrontFn fn;
  int lanes;
};
std::vector<TreeWavefrontEngine> AvailableTreeWavefronts();
TreeWavefrontFn ChosenTreeWavefront();
// The stepper's links as the engines read them.
TreeLinks LinksOf(const TreeStepper& stepper);

}  // namespace flexkin::internal
