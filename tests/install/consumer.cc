// Moves a two-link chain with the installed library; exits 0 only if the lengths are kept.
#include <cstdio>

#include <flexkin/propagate.h>

int main() {
  flexkin::Points points(3, 2);
  points << 0.0, 0.0, 0.0, 1.0, 0.0, 2.0;
  flexkin::Chain chain = flexkin::MakeChain(points);
  flexkin::MoveLeader(flexkin::Method::kTractrix, Eigen::Vector2d(3.0, 0.0), 10, &chain);
  const double error = flexkin::MaxRelativeLengthError(chain);
  std::printf("max relative length error %.3g\n", error);
  return error < 1e-14 ? 0 : 1;
}
