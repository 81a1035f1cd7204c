#include "meshopt/affine_objective.h"

#include <cmath>
#include <limits>

#include "newton_descent.h"

namespace meshopt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

inline Eigen::Matrix2d S_of(const Eigen::Vector2d& x, const AffineTerm& t) { return t.S0 + x * t.c.transpose(); }

inline double det2(const Eigen::Matrix2d& S) { return S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0); }

// h(sigma) in the stable form of Eq. 28 and its first two derivatives.
inline void regularized(double sigma, double delta, double& h, double& dh, double& d2h) {
  if (delta == 0.0) {
    h = sigma, dh = 1.0, d2h = 0.0;
    return;
  }
  const double four_d2 = 4.0 * delta * delta;
  const double r = std::sqrt(sigma * sigma + four_d2);
  h = sigma >= 0.0 ? 0.5 * (sigma + r) : 0.5 * four_d2 / (r - sigma);
  dh = h / r;
  d2h = 0.5 * four_d2 / (r * r * r);
}

struct AffineObjective {
  std::span<const AffineTerm> terms;
  double min_sigma(const Eigen::Vector2d& x) const { return affine_min_sigma(x, terms); }
  double mean_abs_sigma(const Eigen::Vector2d& x) const {
    double s = 0.0;
    for (const AffineTerm& t : terms) s += std::abs(det2(S_of(x, t)));
    return terms.empty() ? 0.0 : s / static_cast<double>(terms.size());
  }
  ObjectiveValue full(const Eigen::Vector2d& x, double delta) const { return affine_objective(x, terms, delta); }
  double value(const Eigen::Vector2d& x, double delta) const { return affine_objective_value(x, terms, delta); }
};

}  // namespace

double affine_min_sigma(const Eigen::Vector2d& x, std::span<const AffineTerm> terms) {
  double m = kInf;
  for (const AffineTerm& t : terms) {
    const double s = det2(S_of(x, t));
    if (s < m || std::isnan(s)) m = s;
  }
  return m;
}

double affine_objective_value(const Eigen::Vector2d& x, std::span<const AffineTerm> terms, double delta) {
  double value = 0.0;
  for (const AffineTerm& t : terms) {
    const Eigen::Matrix2d S = S_of(x, t);
    const double sigma = det2(S);
    if (delta == 0.0 && !(sigma > 0.0)) return kInf;
    double h, dh, d2h;
    regularized(sigma, delta, h, dh, d2h);
    const double eta = S.squaredNorm() / (2.0 * h);
    value += t.weight * (t.power == 1.0 ? eta : std::pow(eta, t.power));
  }
  return value;
}

ObjectiveValue affine_objective(const Eigen::Vector2d& x, std::span<const AffineTerm> terms, double delta) {
  ObjectiveValue out;
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  double value = 0.0;
  for (const AffineTerm& t : terms) {
    const Eigen::Matrix2d S = S_of(x, t);
    const double sigma = det2(S);
    if (delta == 0.0 && !(sigma > 0.0)) {
      out.value = kInf;
      return out;
    }
    double h, dh, d2h;
    regularized(sigma, delta, h, dh, d2h);
    // adj(S0)^T c: sigma(x) = det S0 + c^T adj(S0) x, and adj is linear with
    // c^T adj(x c^T) = 0 for 2x2, so adj(S)^T c gives the same constant gradient.
    const Eigen::Vector2d gs(S(1, 1) * t.c.x() - S(1, 0) * t.c.y(), -S(0, 1) * t.c.x() + S(0, 0) * t.c.y());
    const double f = S.squaredNorm();
    const Eigen::Vector2d gf = 2.0 * S * t.c;
    const double c2 = t.c.squaredNorm();
    const double w = t.weight, invh = 1.0 / h, inv2h = 0.5 * invh;
    const double a1 = dh * inv2h * invh;                             // h' / (2 h^2)
    const double a2 = f * invh * invh * (dh * dh * invh - 0.5 * d2h);  // f (h'^2/h^3 - h''/(2h^2))
    // eta = f / (2h) and its derivatives (cf. the triangle objective's header).
    const double eta = f * inv2h;
    const Eigen::Vector2d geta = gf * inv2h - f * a1 * gs;
    const Eigen::Matrix2d Heta = 2.0 * c2 * inv2h * Eigen::Matrix2d::Identity() -
                                 a1 * (gf * gs.transpose() + gs * gf.transpose()) + a2 * gs * gs.transpose();
    if (t.power == 1.0) {
      value += w * eta;
      g += w * geta;
      H += w * Heta;
    } else {
      // w eta^p: grad = p eta^(p-1) grad eta, Hess = p eta^(p-1) Hess eta + p (p-1) eta^(p-2) grad grad^T.
      const double p = t.power, ep1 = std::pow(eta, p - 1.0);
      value += w * ep1 * eta;
      g += w * p * ep1 * geta;
      H += w * (p * ep1 * Heta + p * (p - 1.0) * ep1 / eta * geta * geta.transpose());
    }
  }
  out.value = value;
  out.gradient = g;
  out.hessian = H;
  return out;
}

Eigen::Vector2d optimize_affine_point(const Eigen::Vector2d& start, std::span<const AffineTerm> terms, double length,
                                      const SmoothingOptions& options) {
  detail::validate_options(options);
  if (terms.empty()) return start;
  detail::Counters cnt;
  return detail::newton_descent(start, AffineObjective{terms}, options, length, cnt);
}

}  // namespace meshopt
