// Local objective K*_tau of one free node (Brovka 2013 Eqs. 3-5) with analytic
// derivatives (cf. Gargallo-Peiro Appendix C, specialized to the plane).
//
// Per triangle (x, a, b): A = (p_a - x, p_b - x), S = A W^{-1}.
//   dA/dx = -e1 (1,1), dA/dy = -e2 (1,1)  =>  dS/dx_i = -e_i c^T,  c = W^{-T} (1,1)^T.
//   f = |S|^2:        grad f = -2 S c,      Hess f = 2 |c|^2 I.
//   sigma = det A det W^{-1} is affine in x: grad sigma = det W^{-1} (a_y - b_y, b_x - a_x).
//   h(sigma) = (sigma + r)/2, r = sqrt(sigma^2 + 4 delta^2):  h' = h / r,  h'' = 2 delta^2 / r^3.
//   term = w f / (2h):
//     grad = w [ grad f / (2h) - f h' grad sigma / (2h^2) ]
//     Hess = w [ Hess f / (2h) - h'/(2h^2) (grad f gs^T + gs grad f^T)
//                + f (h'^2/h^3 - h''/(2h^2)) gs gs^T ]
#include "meshopt/local_objective.h"

#include <cmath>
#include <limits>

namespace meshopt {
namespace {

struct TriangleTerms {
  double sigma;
  double f;
  Eigen::Vector2d grad_sigma;
  Eigen::Vector2d grad_f;
  double c2;  // |c|^2, Hess f = 2 c2 I
};

inline double sigma_of(const Eigen::Vector2d& x, const Eigen::Vector2d& pa, const Eigen::Vector2d& pb,
                       const Eigen::Matrix2d& winv) {
  const double ax = pa.x() - x.x(), ay = pa.y() - x.y();
  const double bx = pb.x() - x.x(), by = pb.y() - x.y();
  return (ax * by - ay * bx) * (winv(0, 0) * winv(1, 1) - winv(0, 1) * winv(1, 0));
}

/// S = A W^{-1} for the triangle (x, a, b).
inline Eigen::Matrix2d s_of(const Eigen::Vector2d& x, const Eigen::Vector2d& pa, const Eigen::Vector2d& pb,
                            const Eigen::Matrix2d& winv) {
  Eigen::Matrix2d a;
  a << pa.x() - x.x(), pb.x() - x.x(), pa.y() - x.y(), pb.y() - x.y();
  return a * winv;
}

inline double frob2_of(const Eigen::Vector2d& x, const Eigen::Vector2d& pa, const Eigen::Vector2d& pb,
                       const Eigen::Matrix2d& winv) {
  return s_of(x, pa, pb, winv).squaredNorm();
}

inline TriangleTerms terms_of(const Eigen::Vector2d& x, const Eigen::Vector2d& pa, const Eigen::Vector2d& pb,
                              const Eigen::Matrix2d& winv) {
  const Eigen::Matrix2d S = s_of(x, pa, pb, winv);
  const Eigen::Vector2d c(winv(0, 0) + winv(1, 0), winv(0, 1) + winv(1, 1));  // c = W^{-T} (1, 1)^T
  const double detw = winv(0, 0) * winv(1, 1) - winv(0, 1) * winv(1, 0);
  TriangleTerms t;
  t.sigma = sigma_of(x, pa, pb, winv);
  t.f = S.squaredNorm();
  t.grad_sigma = Eigen::Vector2d(detw * (pa.y() - pb.y()), detw * (pb.x() - pa.x()));
  t.grad_f = -2.0 * S * c;
  t.c2 = c.squaredNorm();
  return t;
}

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

double min_sigma(const Eigen::Vector2d& x, std::span<const Eigen::Vector2d> positions,
                 std::span<const LocalTriangle> triangles) {
  double m = kInf;
  for (const LocalTriangle& t : triangles) {
    const double s = sigma_of(x, positions[t.a], positions[t.b], t.ideal_inv);
    if (s < m || std::isnan(s)) m = s;
  }
  return m;
}

double local_objective_value(const Eigen::Vector2d& x, std::span<const Eigen::Vector2d> positions,
                             std::span<const LocalTriangle> triangles, double delta) {
  const double four_d2 = 4.0 * delta * delta;
  double value = 0.0;
  for (const LocalTriangle& t : triangles) {
    const Eigen::Vector2d& pa = positions[t.a];
    const Eigen::Vector2d& pb = positions[t.b];
    const double sigma = sigma_of(x, pa, pb, t.ideal_inv);
    double h;
    if (delta == 0.0) {
      if (!(sigma > 0.0)) return kInf;
      h = sigma;
    } else {
      const double r = std::sqrt(sigma * sigma + four_d2);
      h = sigma >= 0.0 ? 0.5 * (sigma + r) : 0.5 * four_d2 / (r - sigma);  // stable form, Eq. 28
    }
    value += t.weight * frob2_of(x, pa, pb, t.ideal_inv) / (2.0 * h);
  }
  return value;
}

ObjectiveValue local_objective(const Eigen::Vector2d& x, std::span<const Eigen::Vector2d> positions,
                               std::span<const LocalTriangle> triangles, double delta) {
  ObjectiveValue out;
  const double four_d2 = 4.0 * delta * delta;
  double g0 = 0, g1 = 0, h00 = 0, h01 = 0, h11 = 0, value = 0;
  for (const LocalTriangle& t : triangles) {
    const TriangleTerms tt = terms_of(x, positions[t.a], positions[t.b], t.ideal_inv);
    double h, dh, d2h;
    if (delta == 0.0) {
      if (!(tt.sigma > 0.0)) {
        out.value = kInf;
        return out;
      }
      h = tt.sigma;
      dh = 1.0;
      d2h = 0.0;
    } else {
      const double r = std::sqrt(tt.sigma * tt.sigma + four_d2);
      h = tt.sigma >= 0.0 ? 0.5 * (tt.sigma + r) : 0.5 * four_d2 / (r - tt.sigma);
      dh = h / r;                    // = (1 + sigma/r)/2
      d2h = 0.5 * four_d2 / (r * r * r);  // = 2 delta^2 / r^3
    }
    const double w = t.weight;
    const double invh = 1.0 / h;
    const double inv2h = 0.5 * invh;
    const double a1 = dh * inv2h * invh;                                   // h' / (2 h^2)
    const double a2 = tt.f * invh * invh * (dh * dh * invh - 0.5 * d2h);  // f (h'^2/h^3 - h''/(2h^2))
    const Eigen::Vector2d& gs = tt.grad_sigma;
    const Eigen::Vector2d& gf = tt.grad_f;
    value += w * tt.f * inv2h;
    g0 += w * (gf.x() * inv2h - tt.f * a1 * gs.x());
    g1 += w * (gf.y() * inv2h - tt.f * a1 * gs.y());
    const double hf = 2.0 * tt.c2 * inv2h;
    h00 += w * (hf - 2.0 * a1 * gf.x() * gs.x() + a2 * gs.x() * gs.x());
    h11 += w * (hf - 2.0 * a1 * gf.y() * gs.y() + a2 * gs.y() * gs.y());
    h01 += w * (-a1 * (gf.x() * gs.y() + gs.x() * gf.y()) + a2 * gs.x() * gs.y());
  }
  out.value = value;
  out.gradient = Eigen::Vector2d(g0, g1);
  out.hessian << h00, h01, h01, h11;
  return out;
}

}  // namespace meshopt
