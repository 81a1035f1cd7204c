// Limited-memory BFGS with memory kept across calls; see lbfgs.h.
#include "tspline/detail/lbfgs.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tspline::detail {

// d = -H g by the two-loop recursion (Nocedal & Wright, Algorithm 7.4), with
// H_0 = gamma I; without pairs, a steepest-descent step.
void Lbfgs::direction(const Eigen::VectorXd& g, Eigen::VectorXd& d) const {
  const int k = pairs();
  d = g;
  std::vector<double> alpha(static_cast<std::size_t>(k));
  for (int i = k - 1; i >= 0; --i) {
    alpha[i] = rho_[i] * s_[i].dot(d);
    d -= alpha[i] * y_[i];
  }
  if (gamma_ > 0.0) {
    d *= gamma_;
  } else {
    // No scale known yet: the largest coordinate moves by 1e-3 (the variables
    // are of order 1); the line search corrects it.
    const double gmax = g.cwiseAbs().maxCoeff();
    if (gmax > 0.0) d *= 1e-3 / gmax;
  }
  for (int i = 0; i < k; ++i) {
    const double beta = rho_[i] * y_[i].dot(d);
    d += (alpha[i] - beta) * s_[i];
  }
  d = -d;
}

Lbfgs::Result Lbfgs::run(Eigen::VectorXd& x, const Objective& f, int max_iterations, double relative_decrease) {
  Result res;
  const Eigen::Index n = x.size();
  Eigen::VectorXd g(n), d(n), xt(n), gt(n);
  double E = f(x.data(), g.data());
  ++res.evaluations;
  res.value = E;
  if (!std::isfinite(E)) return res;
  constexpr double c1 = 1e-4;  // Armijo's sufficient decrease
  while (res.iterations < max_iterations) {
    // Stationary to round-off (the identity map of a square): a step would be
    // noise that Armijo's test cannot tell from a decrease (1 + 1e-17 == 1).
    if (g.cwiseAbs().maxCoeff() <= 1e-12 * std::abs(E)) {
      res.converged = true;
      break;
    }
    direction(g, d);
    double slope = g.dot(d);
    if (!(slope < 0.0)) {  // the pairs went bad (round-off): start over
      reset();
      direction(g, d);
      slope = g.dot(d);
      if (!(slope < 0.0)) break;  // stationary
    }
    bool accepted = false;
    double Et = E;
    double a = 1.0;
    for (int trial = 0; trial < 40; ++trial) {
      xt = x + a * d;
      Et = f(xt.data(), gt.data());
      ++res.evaluations;
      if (std::isfinite(Et) && Et <= E + c1 * a * slope) {
        accepted = true;
        break;
      }
      // Back off: to the minimum of the quadratic through E, the slope and
      // Et (within [a / 10, a / 2]), or halve where the point was refused.
      double next = 0.5 * a;
      if (std::isfinite(Et)) {
        const double curvature = Et - E - slope * a;
        if (curvature > 0.0) next = std::clamp(-slope * a * a / (2.0 * curvature), 0.1 * a, 0.5 * a);
      }
      a = next;
    }
    if (!accepted) {
      if (pairs() == 0) break;
      reset();  // try once more from steepest descent
      continue;
    }
    ++res.iterations;
    // The new pair (s, y); kept only with positive curvature.
    Eigen::VectorXd s = xt - x, y = gt - g;
    const double sy = s.dot(y), yy = y.squaredNorm();
    if (sy > 1e-12 * std::sqrt(s.squaredNorm() * yy) && yy > 0.0) {
      if (static_cast<int>(s_.size()) == memory_) {
        s_.pop_front(), y_.pop_front(), rho_.pop_front();
      }
      s_.push_back(std::move(s));
      y_.push_back(std::move(y));
      rho_.push_back(1.0 / sy);
      gamma_ = sy / yy;
    }
    const double decrease = E - Et;
    x.swap(xt);
    g.swap(gt);
    E = Et;
    res.value = E;
    if (decrease <= relative_decrease * std::abs(E)) {
      res.converged = true;
      break;
    }
  }
  return res;
}

}  // namespace tspline::detail
