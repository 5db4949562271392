#pragma once
// How the contact peers (contact_peer.h, overall_contact_peer.h) run IPOPT: to its tolerance
// 1e-14 with a limited-memory Hessian, the inequality bounds as they are (no relaxation), silent.
#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

namespace flexkin::peers {

// Solves `nlp` so; true if IPOPT reports success (or an acceptable level).
inline bool SolveTightly(const Ipopt::SmartPtr<Ipopt::TNLP>& nlp, int max_iterations) {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetNumericValue("tol", 1e-14);
  app->Options()->SetNumericValue("constr_viol_tol", 1e-14);
  app->Options()->SetStringValue("hessian_approximation", "limited-memory");
  // The constraints as they are: IPOPT relaxes bounds by 1e-8 unless told not to.
  app->Options()->SetNumericValue("bound_relax_factor", 0.0);
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetIntegerValue("max_iter", max_iterations);
  if (app->Initialize() != Ipopt::Solve_Succeeded) return false;
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(nlp);
  return status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
}

}  // namespace flexkin::peers
