#pragma once
// The per-node descent shared by the triangle and the affine-term objectives
// (private to libmeshopt): delta from the smallest sigma (Gargallo-Peiro
// Appendix B, corrected Eq. 38), Newton steps with Armijo backtracking and a
// gradient fallback, delta set to 0 as soon as every sigma is positive.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>

#include "meshopt/local_objective.h"
#include "meshopt/node_smoother.h"
#include "meshopt/triangle_measure.h"

namespace meshopt::detail {

/// True iff H is symmetric positive definite with eigenvalue ratio above a relative threshold.
inline bool is_spd(const Eigen::Matrix2d& H) {
  const double a = H(0, 0), b = 0.5 * (H(0, 1) + H(1, 0)), d = H(1, 1);
  const double mean = 0.5 * (a + d);
  const double rad = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  const double lmax = mean + rad, lmin = mean - rad;
  return std::isfinite(lmax) && lmax > 0.0 && lmin > 1e-12 * lmax;
}

/// \throw toolkit::InputError (a std::invalid_argument) for out-of-range options.
void validate_options(const SmoothingOptions& o);

struct Counters {
  std::size_t newton = 0;
  std::size_t gradient = 0;
};

/// Objective must provide:
///   double min_sigma(x), double mean_abs_sigma(x),
///   ObjectiveValue full(x, delta), double value(x, delta).
template <class Objective>
Eigen::Vector2d newton_descent(const Eigen::Vector2d& start, const Objective& obj, const SmoothingOptions& opt,
                               double L, Counters& cnt) {
  if (!(L > 0.0) || !std::isfinite(L) || !start.allFinite()) return start;
  const double sigma_star = obj.min_sigma(start);
  if (std::isnan(sigma_star)) return start;
  // The typical |sigma| is only needed when sigma* == 0 exactly.
  double delta = untangling_delta(sigma_star, opt.alpha, sigma_star == 0.0 ? obj.mean_abs_sigma(start) : 0.0);
  const double tiny_step = std::max(1e-12, 1e-3 * opt.relative_displacement_tolerance) * L;
  // After a full Newton step of length s on the unmodified measure the remaining error is
  // O(s^2 / L) (quadratic convergence), so a step below 1e-1 * tolerance ends the visit.
  const double newton_stop = std::max(1e-12, 1e-1 * opt.relative_displacement_tolerance) * L;

  Eigen::Vector2d x = start;
  for (int it = 0; it < opt.newton_iterations_per_visit; ++it) {
    const ObjectiveValue ov = obj.full(x, delta);
    const Eigen::Vector2d& g = ov.gradient;
    const double gn = g.norm();
    if (!std::isfinite(ov.value) || !std::isfinite(gn) || gn == 0.0) break;

    Eigen::Vector2d d;
    bool newton = is_spd(ov.hessian);
    if (newton) {
      const Eigen::Matrix2d& H = ov.hessian;
      const double det = H(0, 0) * H(1, 1) - H(0, 1) * H(1, 0);
      d = -Eigen::Vector2d(H(1, 1) * g.x() - H(0, 1) * g.y(), -H(1, 0) * g.x() + H(0, 0) * g.y()) / det;
      if (!d.allFinite() || !(g.dot(d) < 0.0)) newton = false;
    }
    if (!newton) d = -g * (L / gn);  // gradient step of initial length L
    // Armijo backtracking along d, capped at one local length (trust cap).
    double t = 1.0;
    Eigen::Vector2d xn;
    auto line_search = [&](Eigen::Vector2d dir) {
      const double dn = dir.norm();
      if (dn > L) dir *= L / dn;
      const double slope = g.dot(dir);
      t = 1.0;
      for (int k = 0; k <= opt.max_backtracks; ++k, t *= 0.5) {
        xn = x + t * dir;
        const double fn = obj.value(xn, delta);
        if (std::isfinite(fn) && fn <= ov.value + opt.armijo_c * t * slope) return true;
      }
      return false;
    };
    bool accepted = line_search(d);
    // A Newton direction can fail where the gradient does not (e.g. it leaves a
    // constrained domain, where the value is +infinity): try the gradient once.
    if (!accepted && newton) {
      newton = false;
      accepted = line_search(-g * (L / gn));
    }
    if (!accepted) break;
    ++(newton ? cnt.newton : cnt.gradient);
    const double step = (xn - x).norm();
    x = xn;
    // Once the submesh is valid the paper optimizes the unmodified measure (delta = 0).
    if (delta > 0.0 && obj.min_sigma(x) > 0.0) {
      delta = 0.0;
      continue;
    }
    if (step < tiny_step || (newton && t == 1.0 && delta == 0.0 && step < newton_stop)) break;
  }
  return x;
}

}  // namespace meshopt::detail
