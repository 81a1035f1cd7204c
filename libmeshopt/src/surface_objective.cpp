// Local objective of a free node on a parameterized surface, with the chain rule
// through phi (Gargallo-Peiro Sect. 4.2 and Appendix C).
#include "meshopt/surface_objective.h"

#include <cmath>
#include <limits>

namespace meshopt {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

double surface_min_sigma(const Eigen::Vector3d& x, std::span<const SurfaceTerm> terms) {
  double m = kInf;
  for (const SurfaceTerm& t : terms) {
    // f is irrelevant here; triangle_invariants computes both cheaply.
    const double s = triangle_invariants(x, t.xa, t.xb, t.ideal_inv, t.normal, true).sigma;
    if (s < m || std::isnan(s)) m = s;
  }
  return m;
}

double surface_objective_value(const Eigen::Vector2d& u, const ParametricSurface& surface,
                               std::span<const SurfaceTerm> terms, SurfaceMeasure measure, double delta) {
  if (!u.allFinite() || !surface.contains(u)) return kInf;
  const Eigen::Vector3d x = surface.value(u);
  double value = 0.0;
  for (const SurfaceTerm& t : terms) {
    const TriangleInvariants inv = triangle_invariants(x, t.xa, t.xb, t.ideal_inv, t.normal, true);
    const double eta = distortion(measure, inv.f, inv.sigma, delta).value;
    if (!std::isfinite(eta)) return kInf;
    value += t.weight * eta;
  }
  return value;
}

ObjectiveValue surface_objective(const Eigen::Vector2d& u, const ParametricSurface& surface,
                                 std::span<const SurfaceTerm> terms, SurfaceMeasure measure, double delta) {
  ObjectiveValue out;
  if (!u.allFinite() || !surface.contains(u)) {
    out.value = kInf;
    return out;
  }
  const SurfacePoint p = surface.evaluate(u, 2);
  double value = 0.0;
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (const SurfaceTerm& t : terms) {
    const DistortionInX d = restricted_distortion(measure, p.x, t.xa, t.xb, t.ideal_inv, t.normal, delta);
    if (!std::isfinite(d.value)) {
      out.value = kInf;
      return out;
    }
    value += t.weight * d.value;
    g += t.weight * d.gradient;
    H += t.weight * d.hessian;
  }
  out.value = value;
  out.gradient = p.d.transpose() * g;
  // Second-order term of the chain rule: sum_k g_k d2 phi_k / du_a du_b.
  const double guu = g.dot(p.duu), guv = g.dot(p.duv), gvv = g.dot(p.dvv);
  out.hessian = p.d.transpose() * H * p.d;
  out.hessian(0, 0) += guu;
  out.hessian(0, 1) += guv;
  out.hessian(1, 0) += guv;
  out.hessian(1, 1) += gvv;
  return out;
}

}  // namespace meshopt
