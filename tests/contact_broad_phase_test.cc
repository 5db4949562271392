// The contact sweep's broad phase (src/sequential/contact_sweep.cc): colliders farther from the
// head than the chain's length are left out of a sweep only where they cannot lower the least
// clearance measured so far. Checked on the snake of examples/snake_robot_16.urdf (16 links of
// 0.1, pegs grown by its link radius 0.03) threading the 20 pegs of examples/snake_pegs.json: the
// same sweeps with a fresh ContactStats (least clearance +inf, so nothing is left out) give the
// same points bit for bit, and the least clearance over fresh sweeps is the cumulative one.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/vocabulary.h"
#include "sequential/sweep.h"

namespace flexkin {
namespace {

TEST(ContactBroadPhase, SameSweepsBitForBitAndTheSameLeastClearance) {
  constexpr double kPi = 3.14159265358979323846;
  std::vector<Collider> pegs(20);
  for (int k = 0; k < 20; ++k) {
    pegs[k].radius = 0.3;
    pegs[k].margin = 0.03;
    pegs[k].pose.translation() = Eigen::Vector3d(k + 1.0, 0.0, 0.0);
  }
  const int n = 16;
  std::vector<double> lengths(n, 0.1), inv(n, 10.0);
  std::vector<double> a(2 * (n + 1)), b;
  for (int i = 0; i <= n; ++i) a[2 * i] = -0.1 * i, a[2 * i + 1] = -0.5;
  b = a;
  internal::ContactStats cumulative;
  double least_fresh = std::numeric_limits<double>::infinity();
  long long contacts_fresh = 0;
  for (int step = 1; step <= 21 * 160; ++step) {
    const double x = step / 160.0;
    const double head[2] = {x, 0.5 * std::sin(kPi * (x - 0.5))};
    internal::ContactSweep(Method::kTractrix, 2, head, lengths.data(), inv.data(), n, a.data(),
                           pegs, &cumulative);
    internal::ContactStats fresh;
    internal::ContactSweep(Method::kTractrix, 2, head, lengths.data(), inv.data(), n, b.data(),
                           pegs, &fresh);
    least_fresh = std::fmin(least_fresh, fresh.least_clearance);
    contacts_fresh += fresh.contact_link_steps;
    ASSERT_TRUE(a == b) << "step " << step;
  }
  EXPECT_EQ(cumulative.least_clearance, least_fresh);
  EXPECT_EQ(cumulative.contact_link_steps, contacts_fresh);
  EXPECT_GT(contacts_fresh, 1000);
}

}  // namespace
}  // namespace flexkin
