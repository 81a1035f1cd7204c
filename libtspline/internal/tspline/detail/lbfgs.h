#pragma once
// Internal to libtspline: limited-memory BFGS (Nocedal & Wright, Numerical
// Optimization, 2nd ed., Algorithm 7.4 and 7.5) with a backtracking Armijo
// line search, for the eps stages of the map's untangling (map_untangling.h).
//
// Unlike a fresh solver per stage, one Lbfgs keeps its curvature pairs from
// one call of run() to the next: consecutive stages minimize nearby energies
// (eps lowered by a factor), so the pairs of the last stage are a good start
// for the next one instead of a steepest-descent restart. reset() forgets
// them (after the energy changed more than that: new samples, a new power).
//
// The objective may refuse a point (return +infinity or NaN: a barrier, e.g. a
// sample with det J <= 0 at the floor eps); the line search then backs off.
// A pair is stored only if its curvature s^T y is positive (else skipped,
// which keeps the inverse Hessian approximation positive definite without a
// Wolfe curvature condition).
#include <Eigen/Core>
#include <deque>
#include <functional>

namespace tspline::detail {

class Lbfgs {
 public:
  /// f(x, g): the value at x and, into g (never null here), the gradient;
  /// +infinity or NaN where x is not admissible.
  using Objective = std::function<double(const double* x, double* g)>;

  explicit Lbfgs(int memory = 8) : memory_(memory) {}
  void reset() {
    s_.clear(), y_.clear(), rho_.clear();
    gamma_ = 0.0;
  }

  struct Result {
    int iterations = 0;
    int evaluations = 0;
    double value = 0.0;  ///< at the returned x
    bool converged = false;  ///< stopped by the relative decrease test, not the iteration limit
  };

  /// At most max_iterations iterations from x (replaced by the last accepted
  /// point). Stops early when an iteration lowers f by less than
  /// relative_decrease |f|, or when no step along the direction is accepted.
  Result run(Eigen::VectorXd& x, const Objective& f, int max_iterations, double relative_decrease = 0.0);

  int pairs() const { return static_cast<int>(s_.size()); }

 private:
  void direction(const Eigen::VectorXd& g, Eigen::VectorXd& d) const;

  int memory_;
  std::deque<Eigen::VectorXd> s_, y_;
  std::deque<double> rho_;
  double gamma_ = 0.0;  // scaling of the initial inverse Hessian, s^T y / y^T y of the newest pair
};

}  // namespace tspline::detail
