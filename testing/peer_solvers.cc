#include "peer_solvers.h"

#include <nlopt.h>

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "peer_internal.h"

namespace flexkin::peers {
namespace internal {

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double ConstraintViolation(const Eigen::VectorXd& lengths, const Points& x) {
  double worst = 0.0;
  for (Eigen::Index i = 1; i < x.rows(); ++i) {
    const double l = lengths[i - 1];
    worst = std::fmax(worst,
                      std::fabs(((x.row(i) - x.row(i - 1)).squaredNorm() - l * l) / (2 * l * l)));
  }
  return worst;
}

void ValidateInput(const Eigen::VectorXd& lengths, const Eigen::Ref<const Eigen::VectorXd>& head,
                   const PeerOptions& options, const Points& old_points) {
  ValidateChain(Chain{old_points, lengths}, "points");
  if (head.size() != old_points.cols() || !head.allFinite()) {
    throw InputError("head", "must be " + std::to_string(old_points.cols()) +
                                 " finite coordinates, like the chain's points");
  }
  Problems problems;
  AppendNested("options", options.Validate(), &problems);
  ThrowIfAny(problems);
  if (options.weights.joint_angle > 0.0 && old_points.cols() != 2) {
    throw InputError("weights.joint_angle", "is defined for planar (2D) chains only; set it to 0");
  }
}

void SetCommonIpoptOptions(const PeerOptions& options, Ipopt::OptionsList* o) {
  o->SetIntegerValue("print_level", 0);
  o->SetStringValue("sb", "yes");
  o->SetNumericValue("tol", options.ipopt_tolerance);
  o->SetIntegerValue("max_iter", options.max_iterations);
  o->SetStringValue("linear_solver", "mumps");
  o->SetStringValue("hessian_approximation", options.exact_hessian ? "exact" : "limited-memory");
  if (options.max_seconds > 0.0) o->SetNumericValue("max_cpu_time", options.max_seconds);
}

const char* IpoptStatusName(int status) {
  static const std::pair<Ipopt::ApplicationReturnStatus, const char*> kNames[] = {
      {Ipopt::Solve_Succeeded, "Solve_Succeeded"},
      {Ipopt::Solved_To_Acceptable_Level, "Solved_To_Acceptable_Level"},
      {Ipopt::Infeasible_Problem_Detected, "Infeasible_Problem_Detected"},
      {Ipopt::Search_Direction_Becomes_Too_Small, "Search_Direction_Becomes_Too_Small"},
      {Ipopt::Diverging_Iterates, "Diverging_Iterates"},
      {Ipopt::User_Requested_Stop, "User_Requested_Stop"},
      {Ipopt::Feasible_Point_Found, "Feasible_Point_Found"},
      {Ipopt::Maximum_Iterations_Exceeded, "Maximum_Iterations_Exceeded"},
      {Ipopt::Restoration_Failed, "Restoration_Failed"},
      {Ipopt::Error_In_Step_Computation, "Error_In_Step_Computation"},
      {Ipopt::Maximum_CpuTime_Exceeded, "Maximum_CpuTime_Exceeded"},
      {Ipopt::Not_Enough_Degrees_Of_Freedom, "Not_Enough_Degrees_Of_Freedom"},
      {Ipopt::Invalid_Problem_Definition, "Invalid_Problem_Definition"},
      {Ipopt::Invalid_Option, "Invalid_Option"},
      {Ipopt::Invalid_Number_Detected, "Invalid_Number_Detected"},
      {Ipopt::Unrecoverable_Exception, "Unrecoverable_Exception"},
      {Ipopt::NonIpopt_Exception_Thrown, "NonIpopt_Exception_Thrown"},
      {Ipopt::Insufficient_Memory, "Insufficient_Memory"},
      {Ipopt::Internal_Error, "Internal_Error"},
  };
  for (const auto& [code, name] : kNames) {
    if (code == status) return name;
  }
  return "unknown";
}

}  // namespace internal
namespace {

using internal::Clock;
using internal::ConstraintViolation;
using internal::IpoptStatusName;
using internal::SecondsSince;
using internal::ValidateInput;

}  // namespace

// The problem shared by both adapters: the unknowns x_1..x_n flattened row by row (point j's
// coordinates at (j - 1) dim), point 0 pinned at the head.
class StepProblem {
 public:
  StepProblem(const Eigen::VectorXd& lengths, const Eigen::Ref<const Eigen::VectorXd>& head,
              const ObjectiveWeights& weights, const Points& old_points)
      : weights_(weights), lengths_(lengths), old_points_(old_points) {
    // The starting point of OverallStep: the sequential tractrix step.
    Chain chain{old_points, lengths};
    MoveLeader(Method::kTractrix, head, 1, &chain);
    start_ = std::move(chain.points);
    x_ = start_;
  }

  int num_links() const { return static_cast<int>(lengths_.size()); }
  int dim() const { return static_cast<int>(old_points_.cols()); }
  int num_variables() const { return num_links() * dim(); }
  const double* start() const { return start_.data() + dim(); }
  const Eigen::VectorXd& lengths() const { return lengths_; }

  // Makes `v` (num_variables values) the current configuration.
  void Load(const double* v) { std::copy(v, v + num_variables(), x_.data() + dim()); }

  // Objective (and gradient, num_variables values, if not null) at the current configuration.
  double Objective(double* gradient) {
    ++evaluations_;
    if (gradient == nullptr) return OverallObjective(weights_, lengths_, old_points_, x_);
    const double f = OverallObjective(weights_, lengths_, old_points_, x_, &gradient_);
    std::copy(gradient_.data(), gradient_.data() + num_variables(), gradient);
    return f;
  }

  // c_i = (|D_i|^2 - L_i^2) / (2 L_i), i = 1..n, in units of length (about |D_i| - L_i).
  double Constraint(int i) const {
    const double l = lengths_[i - 1];
    return ((x_.row(i) - x_.row(i - 1)).squaredNorm() - l * l) / (2.0 * l);
  }
  // Its gradient: D_i / L_i with respect to x_i, the opposite with respect to x_{i-1}.
  void ConstraintGradient(int i, double* along_link) const {
    for (int a = 0; a < dim(); ++a) along_link[a] = (x_(i, a) - x_(i - 1, a)) / lengths_[i - 1];
  }

  void Hessian(BandedHessian* hessian) const {
    ObjectiveHessianBands(weights_, lengths_, old_points_, x_, hessian);
  }

  void Finish(PeerReport* report) const {
    report->points = x_;
    report->objective = OverallObjective(weights_, lengths_, old_points_, x_);
    report->solver_objective = report->objective;
    report->constraint_violation = ConstraintViolation(lengths_, x_);
    report->evaluations = evaluations_;
  }

 private:
  const ObjectiveWeights& weights_;
  const Eigen::VectorXd& lengths_;
  const Points& old_points_;
  Points start_;
  Points x_;
  Eigen::VectorXd gradient_;
  int evaluations_ = 0;
};

namespace {

// ---- NLopt SLSQP -------------------------------------------------------------------------------

struct SlsqpData {
  StepProblem* problem;
  nlopt_opt opt;
};

// No exception may cross NLopt's C code: a throw becomes a forced stop.
double SlsqpObjective(unsigned /*n*/, const double* v, double* gradient, void* data) {
  auto* d = static_cast<SlsqpData*>(data);
  try {
    d->problem->Load(v);
    return d->problem->Objective(gradient);
  } catch (...) {
    nlopt_force_stop(d->opt);
    return HUGE_VAL;
  }
}

// NLopt's constraint Jacobian is dense, m by n row-major.
void SlsqpConstraints(unsigned m, double* result, unsigned n, const double* v, double* jacobian,
                      void* data) {
  auto* d = static_cast<SlsqpData*>(data);
  StepProblem& p = *d->problem;
  p.Load(v);
  const int dim = p.dim();
  if (jacobian != nullptr) std::fill(jacobian, jacobian + static_cast<size_t>(m) * n, 0.0);
  double e[3];
  for (int i = 1; i <= static_cast<int>(m); ++i) {
    result[i - 1] = p.Constraint(i);
    if (jacobian == nullptr) continue;
    p.ConstraintGradient(i, e);
    double* row = jacobian + static_cast<size_t>(i - 1) * n;
    for (int a = 0; a < dim; ++a) {
      row[(i - 1) * dim + a] = e[a];
      if (i > 1) row[(i - 2) * dim + a] = -e[a];
    }
  }
}

// ---- IPOPT -------------------------------------------------------------------------------------

// The step as an Ipopt::TNLP. Jacobian and Hessian of the Lagrangian are declared with their
// banded patterns (the Hessian's lower triangle: point j with points j - band .. j).
class IpoptStep : public Ipopt::TNLP {
 public:
  IpoptStep(StepProblem* problem, int band) : problem_(problem), band_(band) {}
  // The next solve's problem (ReOptimizeTNLP): the same sizes and band.
  void set_problem(StepProblem* problem) {
    problem_ = problem;
    cached_ = false;
  }

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g,
                    Ipopt::Index& nnz_h_lag, IndexStyleEnum& index_style) override {
    const int links = problem_->num_links(), dim = problem_->dim();
    n = problem_->num_variables();
    m = links;
    nnz_jac_g = (2 * links - 1) * dim;
    nnz_h_lag = 0;
    for (int r = 0; r < n; ++r) nnz_h_lag += r - FirstColumn(r) + 1;
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m,
                       Ipopt::Number* g_l, Ipopt::Number* g_u) override {
    std::fill(x_l, x_l + n, -2e19);  // beyond nlp_lower_bound_inf: no bounds
    std::fill(x_u, x_u + n, 2e19);
    std::fill(g_l, g_l + m, 0.0);
    std::fill(g_u, g_u + m, 0.0);
    return true;
  }

  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z,
                          Ipopt::Number* /*z_L*/, Ipopt::Number* /*z_U*/, Ipopt::Index /*m*/,
                          bool init_lambda, Ipopt::Number* /*lambda*/) override {
    if (init_z || init_lambda) return false;  // only the primal start is known
    if (init_x) std::copy(problem_->start(), problem_->start() + n, x);
    return true;
  }

  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x,
              Ipopt::Number& obj_value) override {
    if (!Update(n, x, new_x)) return false;
    obj_value = value_;
    return true;
  }

  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x,
                   Ipopt::Number* grad_f) override {
    if (!Update(n, x, new_x)) return false;
    std::copy(gradient_.begin(), gradient_.end(), grad_f);
    return true;
  }

  bool eval_g(Ipopt::Index /*n*/, const Ipopt::Number* x, bool new_x, Ipopt::Index m,
              Ipopt::Number* g) override {
    if (new_x) cached_ = false;
    problem_->Load(x);
    for (int i = 1; i <= m; ++i) g[i - 1] = problem_->Constraint(i);
    return true;
  }

  bool eval_jac_g(Ipopt::Index /*n*/, const Ipopt::Number* x, bool new_x, Ipopt::Index m,
                  Ipopt::Index /*nele_jac*/, Ipopt::Index* i_row, Ipopt::Index* j_col,
                  Ipopt::Number* values) override {
    if (new_x) cached_ = false;
    const int dim = problem_->dim();
    int k = 0;
    if (values == nullptr) {
      for (int i = 1; i <= m; ++i) {
        for (int a = 0; a < dim && i > 1; ++a, ++k) i_row[k] = i - 1, j_col[k] = (i - 2) * dim + a;
        for (int a = 0; a < dim; ++a, ++k) i_row[k] = i - 1, j_col[k] = (i - 1) * dim + a;
      }
      return true;
    }
    problem_->Load(x);
    double e[3];
    for (int i = 1; i <= m; ++i) {
      problem_->ConstraintGradient(i, e);
      for (int a = 0; a < dim && i > 1; ++a) values[k++] = -e[a];
      for (int a = 0; a < dim; ++a) values[k++] = e[a];
    }
    return true;
  }

  bool eval_h(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number obj_factor,
              Ipopt::Index /*m*/, const Ipopt::Number* lambda, bool /*new_lambda*/,
              Ipopt::Index /*nele_hess*/, Ipopt::Index* i_row, Ipopt::Index* j_col,
              Ipopt::Number* values) override {
    if (new_x) cached_ = false;
    const int dim = problem_->dim(), links = problem_->num_links();
    int k = 0;
    if (values == nullptr) {
      for (int r = 0; r < n; ++r) {
        for (int c = FirstColumn(r); c <= r; ++c, ++k) i_row[k] = r, j_col[k] = c;
      }
      return true;
    }
    try {
      problem_->Load(x);
      if (obj_factor != 0.0) problem_->Hessian(&hessian_);
    } catch (...) {
      return false;
    }
    // Constraint i's Hessian is (1/L_i) [I, -I; -I, I] on (x_{i-1}, x_i).
    const Eigen::VectorXd& lengths = problem_->lengths();
    for (int r = 0; r < n; ++r) {
      const int j = r / dim + 1, a = r % dim;
      for (int c = FirstColumn(r); c <= r; ++c, ++k) {
        const int t = j - (c / dim + 1), b = c % dim;
        double v = obj_factor == 0.0 ? 0.0 : obj_factor * hessian_.at(j, t, a, b);
        if (a == b && t == 0) {
          v += lambda[j - 1] / lengths[j - 1];
          if (j < links) v += lambda[j] / lengths[j];
        } else if (a == b && t == 1) {
          v -= lambda[j - 1] / lengths[j - 1];
        }
        values[k] = v;
      }
    }
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn /*status*/, Ipopt::Index /*n*/, const Ipopt::Number* x,
                         const Ipopt::Number* /*z_L*/, const Ipopt::Number* /*z_U*/,
                         Ipopt::Index /*m*/, const Ipopt::Number* /*g*/,
                         const Ipopt::Number* /*lambda*/, Ipopt::Number /*obj_value*/,
                         const Ipopt::IpoptData* /*ip_data*/,
                         Ipopt::IpoptCalculatedQuantities* /*ip_cq*/) override {
    problem_->Load(x);
  }

 private:
  // First column of row r in the Hessian's lower-triangle pattern.
  int FirstColumn(int r) const {
    return std::max(0, r / problem_->dim() - band_) * problem_->dim();
  }

  // Objective and gradient at x, computed once per new point. IPOPT's new_x is false when any
  // eval_* method has seen x before, so every one of them clears the cache on a new x.
  bool Update(int n, const double* x, bool new_x) {
    if (!new_x && cached_) return true;
    try {
      problem_->Load(x);
      gradient_.resize(n);
      value_ = problem_->Objective(gradient_.data());
      cached_ = true;
    } catch (...) {
      cached_ = false;
      return false;
    }
    return std::isfinite(value_);
  }

  StepProblem* problem_;
  int band_;
  bool cached_ = false;
  double value_ = 0.0;
  std::vector<double> gradient_;
  BandedHessian hessian_;
};

}  // namespace

Problems PeerOptions::Validate() const {
  Problems problems;
  AppendNested("weights", weights.Validate(), &problems);
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  const auto check = [&](bool ok, const char* field, const char* expected) {
    if (!ok) problems.emplace_back(field, std::string("must be ") + expected, "", expected);
  };
  check(positive(constraint_tolerance), "constraint_tolerance", "a finite number > 0");
  check(xtol_rel >= 0.0, "xtol_rel", ">= 0");
  check(ftol_rel >= 0.0, "ftol_rel", ">= 0");
  check(max_evaluations >= 1, "max_evaluations", ">= 1");
  check(positive(ipopt_tolerance), "ipopt_tolerance", "a finite number > 0");
  check(max_iterations >= 0, "max_iterations", ">= 0");
  check(max_seconds >= 0.0, "max_seconds", ">= 0 (0 for no limit)");
  return problems;
}

std::string PeerReport::BriefReport() const {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%s: %s (%s, code %d): objective %.15g, constraint violation %.2g, %d iterations, "
                "%d evaluations, %.3g s",
                solver.c_str(), converged ? "converged" : "NOT converged", status.c_str(),
                status_code, objective, constraint_violation, iterations, evaluations, seconds);
  return buf;
}

struct SlsqpPeer::State {
  nlopt_opt opt = nullptr;
  SlsqpData data{nullptr, nullptr};
  std::vector<double> x;
};

SlsqpPeer::SlsqpPeer(const Eigen::VectorXd& lengths, int dim, const PeerOptions& options)
    : lengths_(lengths), options_(options), state_(std::make_unique<State>()) {
  const unsigned n = static_cast<unsigned>(lengths.size() * dim);
  const unsigned m = static_cast<unsigned>(lengths.size());
  nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, n);
  if (opt == nullptr) throw std::bad_alloc();
  state_->opt = opt;
  state_->data.opt = opt;
  std::vector<double> tolerances(m);
  for (unsigned i = 0; i < m; ++i) tolerances[i] = options.constraint_tolerance * lengths[i];
  nlopt_set_min_objective(opt, SlsqpObjective, &state_->data);
  nlopt_add_equality_mconstraint(opt, m, SlsqpConstraints, &state_->data, tolerances.data());
  nlopt_set_xtol_rel(opt, options.xtol_rel);
  nlopt_set_ftol_rel(opt, options.ftol_rel);
  nlopt_set_maxeval(opt, options.max_evaluations);
  if (options.max_seconds > 0.0) nlopt_set_maxtime(opt, options.max_seconds);
  state_->x.resize(n);
}

SlsqpPeer::~SlsqpPeer() { nlopt_destroy(state_->opt); }

PeerReport SlsqpPeer::Solve(const Eigen::Ref<const Eigen::VectorXd>& head,
                            const Points& old_points) {
  ValidateInput(lengths_, head, options_, old_points);
  StepProblem problem(lengths_, head, options_.weights, old_points);
  if (problem.num_variables() != static_cast<int>(state_->x.size())) {
    throw InputError("points", "do not match the chain this SLSQP peer was made for");
  }
  PeerReport report;
  report.solver = "slsqp";
  state_->data.problem = &problem;
  std::copy(problem.start(), problem.start() + problem.num_variables(), state_->x.begin());
  double minimum = 0.0;
  const Clock::time_point started = Clock::now();
  const nlopt_result result = nlopt_optimize(state_->opt, state_->x.data(), &minimum);
  report.seconds = SecondsSince(started);
  problem.Load(state_->x.data());  // NLopt returns its best feasible point, not the last one
  problem.Finish(&report);
  report.status_code = result;
  report.status = nlopt_result_to_string(result);
  report.converged =
      result == NLOPT_SUCCESS || result == NLOPT_FTOL_REACHED || result == NLOPT_XTOL_REACHED;
  return report;
}

struct IpoptPeer::State {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app;
  Ipopt::SmartPtr<IpoptStep> nlp;  // made by the first solve, reused by the next ones
  int band = 1;
  int variables = 0;
};

IpoptPeer::IpoptPeer(const Eigen::VectorXd& lengths, int dim, const PeerOptions& options)
    : lengths_(lengths), options_(options), state_(std::make_unique<State>()) {
  state_->band = HessianBand(options.weights, dim);
  state_->variables = static_cast<int>(lengths.size()) * dim;
  // No console journal at all, and no banner: IPOPT must stay silent in the tests.
  state_->app = new Ipopt::IpoptApplication(false);
  Ipopt::SmartPtr<Ipopt::OptionsList> o = state_->app->Options();
  internal::SetCommonIpoptOptions(options, GetRawPtr(o));
  if (options.ipopt_mehrotra) o->SetStringValue("mehrotra_algorithm", "yes");
  const Ipopt::ApplicationReturnStatus status = state_->app->Initialize("");  // no ipopt.opt
  if (status != Ipopt::Solve_Succeeded) {
    throw std::runtime_error(std::string("IPOPT did not initialize: ") + IpoptStatusName(status));
  }
}

IpoptPeer::~IpoptPeer() = default;

PeerReport IpoptPeer::Solve(const Eigen::Ref<const Eigen::VectorXd>& head,
                            const Points& old_points) {
  ValidateInput(lengths_, head, options_, old_points);
  StepProblem problem(lengths_, head, options_.weights, old_points);
  if (problem.num_variables() != state_->variables) {
    throw InputError("points", "do not match the chain this IPOPT peer was made for");
  }
  PeerReport report;
  report.solver = "ipopt";
  Ipopt::ApplicationReturnStatus status = Ipopt::Internal_Error;
  const bool first = Ipopt::IsNull(state_->nlp);
  if (first) {
    state_->nlp = new IpoptStep(&problem, state_->band);
  } else {
    state_->nlp->set_problem(&problem);
  }
  const Ipopt::SmartPtr<Ipopt::TNLP> nlp = GetRawPtr(state_->nlp);
  const Clock::time_point started = Clock::now();
  try {
    status = first ? state_->app->OptimizeTNLP(nlp) : state_->app->ReOptimizeTNLP(nlp);
  } catch (const std::bad_alloc&) {
    status = Ipopt::Insufficient_Memory;
  }
  report.seconds = SecondsSince(started);
  if (Ipopt::SmartPtr<Ipopt::SolveStatistics> stats = state_->app->Statistics();
      Ipopt::IsValid(stats)) {
    report.iterations = stats->IterationCount();
  }
  state_->nlp->set_problem(nullptr);
  problem.Finish(&report);
  report.status_code = status;
  report.status = IpoptStatusName(status);
  report.converged = status == Ipopt::Solve_Succeeded;
  return report;
}

PeerReport SolveWithSlsqp(const Eigen::VectorXd& lengths,
                          const Eigen::Ref<const Eigen::VectorXd>& head, const PeerOptions& options,
                          const Points& old_points) {
  ValidateInput(lengths, head, options, old_points);
  return SlsqpPeer(lengths, static_cast<int>(old_points.cols()), options).Solve(head, old_points);
}

PeerReport SolveWithIpopt(const Eigen::VectorXd& lengths,
                          const Eigen::Ref<const Eigen::VectorXd>& head, const PeerOptions& options,
                          const Points& old_points) {
  ValidateInput(lengths, head, options, old_points);
  return IpoptPeer(lengths, static_cast<int>(old_points.cols()), options).Solve(head, old_points);
}

int HessianBand(const ObjectiveWeights& weights, int dim) {
  return weights.joint_angle > 0.0 && dim == 2 ? 2 : 1;
}

Eigen::MatrixXd BandedHessian::ToDense() const {
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n * dim, n * dim);
  for (int j = 1; j <= n; ++j) {
    for (int t = 0; t <= band && j - t >= 1; ++t) {
      for (int r = 0; r < dim; ++r) {
        for (int c = 0; c < dim; ++c) {
          h((j - 1) * dim + r, (j - t - 1) * dim + c) = at(j, t, r, c);
          h((j - t - 1) * dim + c, (j - 1) * dim + r) = at(j, t, r, c);
        }
      }
    }
  }
  return h;
}

// Window k pins point s - 1 and frees points s..e, and OverallObjective on it has every term of
// the whole chain that lies inside. Missing are the joint at s - 1 (it changes block (s, s)) and,
// unless e = n, the terms reaching past e (they change blocks among e - 1 and e). So block rows
// j = s + 1 + band .. e - 2 are exact (from j = 1 when s = 1, to j = n when e = n); windows of
// kWindow points overlap just enough for these rows to tile 1..n.
void ObjectiveHessianBands(const ObjectiveWeights& weights, const Eigen::VectorXd& lengths,
                           const Points& old_points, const Points& new_points,
                           BandedHessian* hessian) {
  constexpr int kWindow = 24;
  const int n = static_cast<int>(lengths.size());
  const int dim = static_cast<int>(new_points.cols());
  const int band = HessianBand(weights, dim);
  hessian->n = n;
  hessian->dim = dim;
  hessian->band = band;
  hessian->blocks.assign(static_cast<size_t>(n) * (band + 1) * dim * dim, 0.0);
  Points window_old, window_new;
  Eigen::MatrixXd h;
  for (int next = 1; next <= n;) {
    const int s = std::max(1, next - 1 - band);
    const int e = std::min(n, s + kWindow - 1);
    const int last = e == n ? n : e - 2;
    window_old = old_points.middleRows(s - 1, e - s + 2);
    window_new = new_points.middleRows(s - 1, e - s + 2);
    OverallObjective(weights, lengths.segment(s - 1, e - s + 1), window_old, window_new, nullptr,
                     &h);
    for (int j = next; j <= last; ++j) {
      for (int t = 0; t <= band && j - t >= 1; ++t) {
        double* block = hessian->blocks.data() + ((j - 1) * (band + 1) + t) * dim * dim;
        for (int r = 0; r < dim; ++r) {
          for (int c = 0; c < dim; ++c)
            block[r * dim + c] = h((j - s) * dim + r, (j - t - s) * dim + c);
        }
      }
    }
    next = last + 1;
  }
}

}  // namespace flexkin::peers
