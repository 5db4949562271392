#pragma once
// KDL's recursive forward kinematics, counting its calls: ChainIkSolverPos_NR evaluates it once
// per iteration (plus once for the final check) and reports no iteration count itself. Shared by
// the KDL peers (kdl_peer.h, kdl_urdf_peer.h).
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

namespace flexkin::peers {

class CountingFk : public KDL::ChainFkSolverPos_recursive {
 public:
  explicit CountingFk(const KDL::Chain& chain) : KDL::ChainFkSolverPos_recursive(chain) {}
  int JntToCart(const KDL::JntArray& q, KDL::Frame& p, int segment = -1) override {
    ++calls;
    return KDL::ChainFkSolverPos_recursive::JntToCart(q, p, segment);
  }
  using KDL::ChainFkSolverPos_recursive::JntToCart;
  int calls = 0;
};

}  // namespace flexkin::peers
