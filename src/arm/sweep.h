#pragma once
// The sweep of the fixed-base arm's step (src/arm/solver.cc, docs/robots.md), for planar arms and
// spatial arms with spherical joints: translate the arm by u, move the end effector in a straight
// line to the target and let every link follow by the tractrix step, from the end effector down
// to the base, putting each link back into its joint's limits as soon as it is placed. F(u) is
// where the base ends minus model.base.
//
// Several translations ("lanes", up to kMaxLanes) can be swept in one pass over the links. The
// link-to-link dependency makes one sweep latency-bound (each link waits for the one before it:
// a sqrt, an exp and a division in a row), so independent lanes interleaved in the same loop cost
// little more than one: a finite-difference Jacobian's dim sweeps run in about the time of one.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "arm/colliders.h"
#include "arm/internal.h"
#include "flexkin/arm.h"

namespace flexkin::arm_internal {

class Sweeper {
 public:
  static constexpr int kMaxLanes = 4;

  // `start` (n+1 by dim, base first) must outlive the sweeper. With `colliders` (grown by the
  // link radius and the skin: src/arm/colliders.h; must outlive the sweeper), every link whose
  // tractrix step (and limits) would put it into one takes the contact step instead, in every
  // lane (the generic loop: the AVX2 lanes are not used). Keyframed ones are placed by their
  // motions at each sub-step's time in `window` (StepWindow::Substep).
  Sweeper(const ArmModel& model, const Points& start, const Eigen::VectorXd& target, int substeps,
          const std::vector<Collider>* colliders = nullptr, const StepWindow& window = {});

  // F(u) (dim); leaves the swept points in points().
  SmallVec Evaluate(const SmallVec& u);
  // The forward-difference Jacobian at u, F(u) being `f`: its dim columns (F(u + h e_k) - f) / h
  // from dim lanes swept in one pass. points() is left as it was.
  void Jacobian(const SmallVec& u, const SmallVec& f, double h, SmallMat* jac);
  // F(u) and the forward-difference Jacobian at u, (F(u + h e_k) - F(u)) / h, from dim + 1 lanes
  // swept in one pass; leaves the points of u in points(). With `probe` (only where
  // spare_lane()), F(probe) into *f_probe from one more lane of the same pass.
  SmallVec EvaluateWithJacobian(const SmallVec& u, double h, SmallMat* jac,
                                const SmallVec* probe = nullptr, SmallVec* f_probe = nullptr);
  // One sweep of the given points in place (the fixed-point baseline translates them itself).
  SmallVec SweepInPlace(Points* points);

  // The points of the last Evaluate (n+1 by dim, base first).
  const Points& points() const { return lanes_[0]; }
  // Whether a joint limit was active in the last Evaluate (or SweepInPlace).
  bool limited() const { return limited_; }
  // Link steps so far that took the contact step (every lane counted), and whether one found
  // every direction blocked (the link was left where the tractrix put it).
  int contacts() const { return contacts_; }
  bool wedged() const { return wedged_; }
  // Sweeps so far, every lane counted (cost ~ passes * n).
  int sweeps() const { return sweeps_; }
  // Passes over the links so far: lanes swept together count once.
  int passes() const { return passes_; }
  // Whether Jacobian lanes cost about one sweep (the AVX2 lanes), not dim sweeps' worth.
  bool cheap_jacobian() const { return fast_; }
  // Whether EvaluateWithJacobian has a lane to spare for a probe at no cost (AVX2 lanes, dim 2).
  bool spare_lane() const { return fast_ && dim_ + 2 <= kMaxLanes; }

 private:
  // Sweeps the K lanes' points in place (each n+1 by dim, row-major); limited[l]: whether a
  // joint limit was active in lane l.
  template <int Dim, int K>
  void Run(double* const* lanes, bool* limited);
  void RunLanes(int lanes, double* const* points, bool* limited);
  // Puts link j (points j-1, j of `p`) back into the limits of joint j and, for the base link, of
  // joint 0, turning it about point j. Returns whether it moved.
  bool Limit(double* p, int j) const;
  // Link j (points j-1, j of `p`) out of `colliders`: where it enters one, its trailing end is
  // moved from `tail_old` by the contact step (world/contact.h).
  template <int Dim>
  void Contact(const std::vector<Collider>& colliders, double* p, int j, const double* tail_old);
  // The AVX2 sweeps of `lanes` translations (u: lanes by dim); copy 0's points into `points0`,
  // the lanes' F into fast_bases_ (lanes by dim). Returns lane 0's F.
  SmallVec FastLanes(int lanes, const double* u, double* points0);

  const ArmModel& model_;
  const Points& start_;
  const Eigen::VectorXd target_;
  const int substeps_, n_, dim_;
  const bool has_limits_;
  bool fast_ = false;                // no limits and the CPU has AVX2 + FMA: src/arm/lanes.h
  double fast_bases_[kMaxLanes][3];  // the lanes' F after FastLanes
  Eigen::VectorXd base_direction_;
  std::vector<double> inv_lengths_;
  std::array<Points, kMaxLanes> lanes_;
  const std::vector<Collider>* colliders_;
  // With keyframed colliders: *colliders_ at the time of each sub-step (empty otherwise).
  std::vector<std::vector<Collider>> posed_;
  bool limited_ = false, wedged_ = false;
  int sweeps_ = 0, passes_ = 0, contacts_ = 0;
};

}  // namespace flexkin::arm_internal
