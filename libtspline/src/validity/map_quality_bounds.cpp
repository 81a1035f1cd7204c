// Certified lower bounds of J_r and of the scaled Jacobian; see
// map_quality_bounds.h for the method and the equation numbers.
#include "tspline/validity/map_quality_bounds.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include "toolkit/errors.h"
#include "toolkit/timing.h"
#include "tspline/detail/bernstein.h"
#include "tspline/detail/element_jacobian.h"
#include "tspline/detail/thread_pool.h"

namespace tspline {

namespace {

using detail::BernsteinPoly;
using detail::binomial;
using detail::kMaxBinomial;
using detail::bernstein_axpy;
using detail::bernstein_ds;
using detail::bernstein_dt;
using detail::bernstein_product;
using detail::bernstein_subdivide;

// Relative round-off allowance (header, "Round-off").
constexpr double kRoundOff = 1e-12;

// J_r (2) and SJ (3) from the values of D w = det(N_s, N_t) and of N_s, N_t at
// a point; r = h_eta / h_xi. Degenerate columns give 0, as mean_ratio_jacobian
// and scaled_jacobian do (map_quality.h).
struct Quality {
  double jr, sj;
};
Quality quality_at(double dw, double nsx, double nsy, double ntx, double nty, double r) {
  const double a2 = nsx * nsx + nsy * nsy, b2 = ntx * ntx + nty * nty;
  const double q = r * a2 + b2 / r, ab = std::sqrt(a2 * b2);
  return {q > 0.0 ? 2.0 * dw / q : 0.0, ab > 0.0 ? dw / ab : 0.0};
}

// A polynomial of bidegree (m, n) <= (12, 12) in the Bernstein basis, for the
// ratio bound (8): A = 2 D w (11,11) and |N_s|^2 (10,12), |N_t|^2 (12,10), all
// elevated to (12,12). (detail::BernsteinPoly stops at (8,8).)
constexpr int kQ = 12;
struct Poly12 {
  int m = 0, n = 0;
  std::array<double, (kQ + 1) * (kQ + 1)> c{};
  Poly12() = default;
  Poly12(int m_, int n_) : m(m_), n(n_) {}
  double& at(int i, int j) { return c[i + (m + 1) * j]; }
  double at(int i, int j) const { return c[i + (m + 1) * j]; }
  int size() const { return (m + 1) * (n + 1); }
};

static_assert(2 * kQ <= kMaxBinomial, "products of degree-kQ polynomials need C(2 kQ, k)");
static_assert(kQ <= detail::kMaxSplitDegree, "bernstein_subdivide splits rows of up to kMaxSplitDegree + 1 values");

Poly12 to_poly12(const BernsteinPoly& p) {
  Poly12 r(p.m, p.n);
  for (int k = 0; k < p.size(); ++k) r.c[k] = p.c[k];
  return r;
}

// The product (B_i^m1 B_k^m2 = binom(m1,i) binom(m2,k) / binom(m1+m2,i+k) B_{i+k}^{m1+m2}, in each direction).
Poly12 product12(const Poly12& a, const Poly12& b) {
  Poly12 r(a.m + b.m, a.n + b.n);
  // Scaled coefficients a_ij binom(m, i) binom(n, j): the product is a plain convolution.
  std::array<double, (kQ + 1) * (kQ + 1)> sa{}, sb{};
  for (int j = 0; j <= a.n; ++j)
    for (int i = 0; i <= a.m; ++i) sa[i + (a.m + 1) * j] = a.at(i, j) * binomial(a.m, i) * binomial(a.n, j);
  for (int j = 0; j <= b.n; ++j)
    for (int i = 0; i <= b.m; ++i) sb[i + (b.m + 1) * j] = b.at(i, j) * binomial(b.m, i) * binomial(b.n, j);
  const int rs = r.m + 1, bs = b.m + 1;
  for (int j1 = 0; j1 <= a.n; ++j1)
    for (int i1 = 0; i1 <= a.m; ++i1) {
      const double x = sa[i1 + (a.m + 1) * j1];
      if (x == 0.0) continue;
      for (int j2 = 0; j2 <= b.n; ++j2) {
        double* out = &r.c[i1 + rs * (j1 + j2)];
        const double* in = &sb[bs * j2];
        for (int i2 = 0; i2 <= b.m; ++i2) out[i2] += x * in[i2];
      }
    }
  for (int j = 0; j <= r.n; ++j)
    for (int i = 0; i <= r.m; ++i) r.at(i, j) /= binomial(r.m, i) * binomial(r.n, j);
  return r;
}

// Degree elevation to (kQ, kQ), one degree at a time:
// c'_i = (i / (m + 1)) c_{i-1} + (1 - i / (m + 1)) c_i.
Poly12 elevate12(Poly12 p) {
  while (p.m < kQ) {
    Poly12 q(p.m + 1, p.n);
    for (int j = 0; j <= p.n; ++j)
      for (int i = 0; i <= q.m; ++i) {
        const double f = static_cast<double>(i) / q.m;
        q.at(i, j) = (i > 0 ? f * p.at(i - 1, j) : 0.0) + (i < q.m ? (1.0 - f) * p.at(i, j) : 0.0);
      }
    p = q;
  }
  while (p.n < kQ) {
    Poly12 q(p.m, p.n + 1);
    for (int j = 0; j <= q.n; ++j) {
      const double f = static_cast<double>(j) / q.n;
      for (int i = 0; i <= p.m; ++i)
        q.at(i, j) = (j > 0 ? f * p.at(i, j - 1) : 0.0) + (j < q.n ? (1.0 - f) * p.at(i, j) : 0.0);
    }
    p = q;
  }
  return p;
}

// One patch (the element or a sub-patch): the components of N_s, N_t (1) and
// A = 2 D w, S2 = |N_s|^2, T2 = |N_t|^2 (8) in the Bernstein basis of the
// patch, and its position in the element.
struct Patch {
  BernsteinPoly nsx, nsy, ntx, nty;
  Poly12 a, s2, t2;     // only if `ratio` (made once the cone bound alone is not enough)
  bool ratio = false;
  int depth = 0;
  double s0 = 0.0, t0 = 0.0, size = 1.0;
  double jr_lo = -1.0, sj_lo = -1.0;  // the patch's lower bounds
};

// Upper and lower bounds (4), (5) of |N| over a patch from the coefficients of
// its two components.
struct NormBounds {
  double hi2 = 0.0;  // >= max |N|^2
  double lo = 0.0;   // <= min |N|
};
NormBounds norm_bounds(const BernsteinPoly& x, const BernsteinPoly& y) {
  const int n = x.size();
  double mx = 0.0, my = 0.0, hi2 = 0.0;
  for (int k = 0; k < n; ++k) {
    mx += x.c[k];
    my += y.c[k];
    hi2 = std::max(hi2, x.c[k] * x.c[k] + y.c[k] * y.c[k]);
  }
  mx /= n;
  my /= n;
  double rad2 = 0.0;
  for (int k = 0; k < n; ++k) {
    const double dx = x.c[k] - mx, dy = y.c[k] - my;
    rad2 = std::max(rad2, dx * dx + dy * dy);
  }
  NormBounds b;
  b.hi2 = hi2 * (1.0 + kRoundOff);
  b.lo = std::max(0.0, (std::sqrt(mx * mx + my * my) - std::sqrt(rad2)) * (1.0 - kRoundOff));
  return b;
}

// The cone of a vector polynomial N = (x, y) (header, (6)): its coefficients
// c_k make angles theta_k with their mean direction m; if every c_k lies in the
// open half-plane dot(c, m) > 0 (and is not tiny, so that its angle is well
// conditioned), N(p) = sum b_k(p) c_k lies in the cone of angles
// [alpha + theta_min, alpha + theta_max], alpha = angle(m), and
// |N(p)| >= dot(N(p), m) >= min_k dot(c_k, m).
struct Cone {
  bool ok = false;
  double lo = 0.0, hi = 0.0;  // absolute angles
  double min_dot = 0.0;       // <= |N| on the patch
};
Cone cone(const BernsteinPoly& x, const BernsteinPoly& y, double max_norm2) {
  // Coefficients below 1e-6 of the largest are not used (their angles are ill
  // conditioned). The coefficients' round-off is taken as 1e3 eps of the
  // largest, so the angle of c_k is off by at most 1e3 eps max|c| / |c_k|:
  // the cone is widened by that (at most 2.2e-7 rad; 2.2e-13 where all
  // coefficients have the same length, as for an affine map).
  constexpr double kTiny2 = 1e-12, kCoefficientRoundOff = 1e3 * std::numeric_limits<double>::epsilon();
  const int n = x.size();
  double mx = 0.0, my = 0.0;
  for (int k = 0; k < n; ++k) mx += x.c[k], my += y.c[k];
  const double mn = std::hypot(mx, my);
  Cone c;
  if (!(mn > 0.0)) return c;
  mx /= mn, my /= mn;
  double tan_lo = 0.0, tan_hi = 0.0, min_dot = std::numeric_limits<double>::infinity(), min_norm2 = max_norm2;
  for (int k = 0; k < n; ++k) {
    const double d = mx * x.c[k] + my * y.c[k], cr = mx * y.c[k] - my * x.c[k], n2 = d * d + cr * cr;
    if (!(d > 0.0) || n2 < kTiny2 * max_norm2) return c;
    // theta_k in (-pi/2, pi/2), increasing with tan theta_k = cr / d.
    const double t = cr / d;
    tan_lo = k ? std::min(tan_lo, t) : t;
    tan_hi = k ? std::max(tan_hi, t) : t;
    min_dot = std::min(min_dot, d);
    min_norm2 = std::min(min_norm2, n2);
  }
  const double widen = kCoefficientRoundOff * std::sqrt(max_norm2 / min_norm2);
  const double alpha = std::atan2(my, mx);
  c.ok = true;
  c.lo = alpha + std::atan(tan_lo) - widen;
  c.hi = alpha + std::atan(tan_hi) + widen;
  c.min_dot = min_dot * (1.0 - kRoundOff);
  return c;
}

// min of sin over [lo, hi] (hi - lo < 2 pi): -1 if the interval holds a
// minimum point -pi/2 + 2 pi k, otherwise the smaller end value.
double min_sin(double lo, double hi) {
  constexpr double pi = 3.14159265358979323846;
  const double p = -0.5 * pi + 2.0 * pi * std::ceil((lo + 0.5 * pi) / (2.0 * pi));
  return p <= hi ? -1.0 : std::min(std::sin(lo), std::sin(hi));
}

// g(t) = 2 t / (1 + t^2), increasing on [0, 1], decreasing beyond (g(inf) = 0).
double g_ratio(double t) { return std::isfinite(t) ? 2.0 * t / (1.0 + t * t) : 0.0; }

// min_k A_k / (alpha S2_k + beta T2_k) over the coefficients (8): a lower
// bound of A / (alpha S2 + beta T2) if every denominator coefficient is > 0,
// otherwise -1. tol_a: the round-off allowance of A.
double ratio_bound(const Patch& p, double alpha, double beta, double tol_a) {
  double lo = 1.0;
  for (int k = 0; k < p.a.size(); ++k) {
    const double q = alpha * p.s2.c[k] + beta * p.t2.c[k];
    if (!(q > 0.0)) return -1.0;
    const double a = p.a.c[k] - tol_a;
    lo = std::min(lo, a / (a >= 0.0 ? q * (1.0 + kRoundOff) : q * (1.0 - kRoundOff)));
  }
  return std::max(-1.0, lo);
}

// The lower bounds of J_r and SJ on a patch: the larger of two valid bounds.
//  (a) The ratio bound (8): J_r >= min_k A_k / (r S2_k + T2_k / r), and
//      SJ >= min_k A_k / (rho S2_k + T2_k / rho) for any rho > 0 if A >= 0 on
//      the patch (all A_k >= 0; AM-GM: rho |N_s|^2 + |N_t|^2 / rho >=
//      2 |N_s| |N_t|), with rho the ratio of the mean coefficients of |N_t|
//      and |N_s| on the patch (the best rho at a point is |N_t| / |N_s|).
//  (b) From the cones (6) of N_s and N_t: the angle phi from N_s to N_t lies in
//      [lo_t - hi_s, hi_t - lo_s], so SJ = sin phi >= sigma = min sin there, and
//      J_r = g(tau) sin phi (7) with tau = |N_t| / (r |N_s|) in
//      [b_lo / (r a_hi), b_hi / (r a_lo)]: J_r >= sigma min(g(tau_lo), g(tau_hi))
//      if sigma >= 0 (g is unimodal), J_r >= sigma otherwise (0 <= g <= 1).
// tol_a is the round-off allowance of A.
void bound_patch(Patch& p, double r, double tol_a) {
  p.jr_lo = p.sj_lo = -1.0;
  // (a)
  if (p.ratio) {
    double ms = 0.0, mt = 0.0;
    for (int k = 0; k < p.s2.size(); ++k) ms += p.s2.c[k], mt += p.t2.c[k];
    const double rho = ms > 0.0 && mt > 0.0 ? std::sqrt(mt / ms) : r;
    p.jr_lo = ratio_bound(p, r, 1.0 / r, tol_a);
    // The AM-GM step needs A >= 0 on the patch (for A < 0 it goes the other way).
    double a_min = p.a.c[0];
    for (int k = 1; k < p.a.size(); ++k) a_min = std::min(a_min, p.a.c[k]);
    if (a_min - tol_a >= 0.0) p.sj_lo = ratio_bound(p, rho, 1.0 / rho, tol_a);
  }
  // (b)
  const NormBounds a = norm_bounds(p.nsx, p.nsy), b = norm_bounds(p.ntx, p.nty);
  const Cone cs = cone(p.nsx, p.nsy, a.hi2), ct = cone(p.ntx, p.nty, b.hi2);
  if (!cs.ok || !ct.ok) return;
  const double sigma = min_sin(ct.lo - cs.hi, ct.hi - cs.lo);
  p.sj_lo = std::max(p.sj_lo, sigma);
  if (sigma < 0.0) {
    p.jr_lo = std::max(p.jr_lo, sigma);
    return;
  }
  const double a_lo = std::max(a.lo, cs.min_dot), b_lo = std::max(b.lo, ct.min_dot);
  const double a_hi = std::sqrt(a.hi2), b_hi = std::sqrt(b.hi2);
  const double tau_lo = b_lo / (r * a_hi), tau_hi = a_lo > 0.0 ? b_hi / (r * a_lo) : HUGE_VAL;
  p.jr_lo = std::max(p.jr_lo, sigma * std::min(g_ratio(tau_lo), g_ratio(tau_hi)) * (1.0 - kRoundOff));
}

// Tabulated cubic Bernstein values and derivatives at k + 1 equispaced points.
struct SampleTable {
  int k = 0;
  std::vector<std::array<double, 4>> b, db;
  explicit SampleTable(int k_) : k(k_) {
    for (int i = 0; i <= k && k > 0; ++i) {
      const double s = static_cast<double>(i) / k, u = 1.0 - s;
      b.push_back({u * u * u, 3.0 * s * u * u, 3.0 * s * s * u, s * s * s});
      db.push_back({-3.0 * u * u, 3.0 * u * u - 6.0 * s * u, 6.0 * s * u - 3.0 * s * s, 3.0 * s * s});
    }
  }
};

// The dense sample of J_r and SJ on the element from X, Y, w (bidegree (3,3),
// coefficient i + 4 j): at every grid point N_s = X_s w - X w_s, N_t likewise (1).
void dense_sample(const std::array<BernsteinPoly, 3>& xyw, const SampleTable& tab, double r,
                  const BezierElement& e, ElementQualityBound& out) {
  const int k = tab.k;
  for (int j = 0; j <= k; ++j) {
    // Contract the t index: v[c][i] = sum_j' coef(i, j') B_j'(t), vt[c][i] with B'.
    double v[3][4], vt[3][4];
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 4; ++i) {
        double a = 0.0, at = 0.0;
        for (int jj = 0; jj < 4; ++jj) {
          a += xyw[c].c[i + 4 * jj] * tab.b[j][jj];
          at += xyw[c].c[i + 4 * jj] * tab.db[j][jj];
        }
        v[c][i] = a;
        vt[c][i] = at;
      }
    for (int i = 0; i <= k; ++i) {
      double f[3], fs[3], ft[3];
      for (int c = 0; c < 3; ++c) {
        f[c] = fs[c] = ft[c] = 0.0;
        for (int ii = 0; ii < 4; ++ii) {
          f[c] += v[c][ii] * tab.b[i][ii];
          fs[c] += v[c][ii] * tab.db[i][ii];
          ft[c] += vt[c][ii] * tab.b[i][ii];
        }
      }
      const double w = f[2];
      const double nsx = fs[0] * w - f[0] * fs[2], nsy = fs[1] * w - f[1] * fs[2];
      const double ntx = ft[0] * w - f[0] * ft[2], nty = ft[1] * w - f[1] * ft[2];
      const Quality q = quality_at(nsx * nty - nsy * ntx, nsx, nsy, ntx, nty, r);
      const Eigen::Vector2d uv(e.lo.x() + (e.hi.x() - e.lo.x()) * i / k, e.lo.y() + (e.hi.y() - e.lo.y()) * j / k);
      if (q.jr < out.mean_ratio.sampled) out.mean_ratio.sampled = q.jr, out.mean_ratio.sampled_at = uv;
      if (q.sj < out.scaled.sampled) out.scaled.sampled = q.sj, out.scaled.sampled_at = uv;
    }
  }
}

void check_options(const QualityBoundOptions& o) {
  if (o.max_depth < 0 || o.max_depth > 20) throw toolkit::InputError("quality bounds: max_depth out of range");
  if (o.max_patches < 1) throw toolkit::InputError("quality bounds: max_patches must be >= 1");
  if (!(o.relative_gap >= 0.0) || !(o.absolute_gap >= 0.0))
    throw toolkit::InputError("quality bounds: the gaps must be >= 0");
  if (o.samples_per_edge < 0) throw toolkit::InputError("quality bounds: samples_per_edge must be >= 0");
}

// The Bernstein forms of one element: D, w and the round-off scale of D as
// the certification computes them, and X, Y, w (bidegree (3,3)).
struct ElementForms {
  detail::ElementJacobian J;
  std::array<BernsteinPoly, 3> xyw;
};

ElementForms element_forms(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                           bool numerator = true) {
  ElementForms f{detail::element_jacobian(e, P, numerator),
                 {BernsteinPoly(3, 3), BernsteinPoly(3, 3), BernsteinPoly(3, 3)}};
  f.xyw[2] = f.J.weight;
  // X, Y relative to the element's mean control point (as element_jacobian:
  // N_s, N_t are translation invariant, X -> X + c w adds c (w_s w - w w_s) = 0).
  const Eigen::Index nf = e.C.rows();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (Eigen::Index a = 0; a < nf; ++a) centre += P[e.functions[a]];
  if (nf > 0) centre /= static_cast<double>(nf);
  for (Eigen::Index a = 0; a < nf; ++a) {
    const Eigen::Vector2d p = P[e.functions[a]] - centre;
    for (int k = 0; k < 16; ++k) {
      f.xyw[0].c[k] += p.x() * e.C(a, k);
      f.xyw[1].c[k] += p.y() * e.C(a, k);
    }
  }
  return f;
}

double aspect(const BezierElement& e) { return (e.hi.y() - e.lo.y()) / (e.hi.x() - e.lo.x()); }

// The dense sample of one element (its forms made again, the same as
// bound_element's): into out's `sampled` fields.
void sample_element(const BezierElement& e, const std::vector<Eigen::Vector2d>& P, const SampleTable& tab,
                    ElementQualityBound& out) {
  dense_sample(element_forms(e, P, false).xyw, tab, aspect(e), e, out);
}

// The bounds of one element, to the gap (to_gap), or only the cone bound (b)
// on the whole element and its corner values (the first step of the former).
ElementQualityBound bound_element(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                  const QualityBoundOptions& opt, const SampleTable& tab,
                                  bool to_gap = true) {
  ElementQualityBound res;
  const double hx = e.hi.x() - e.lo.x(), hy = e.hi.y() - e.lo.y();
  const double r = aspect(e);
  // (The cone bound alone needs D's scale, not D: to_gap makes it.)
  const ElementForms forms = element_forms(e, P, to_gap);
  const detail::ElementJacobian& J = forms.J;
  const std::array<BernsteinPoly, 3>& xyw = forms.xyw;
  const BernsteinPoly& W = xyw[2];
  const BernsteinPoly Ws = bernstein_ds(W), Wt = bernstein_dt(W);
  // (1): N_s = X_s w - X w_s, N_t = X_t w - X w_t per component. Where w is
  // constant (the functions sum to 1 on the element) w_s = w_t = 0: X w_s is
  // +0 everywhere and subtracting it changes no coefficient, so it is not made.
  const bool ws_zero = Ws.is_zero(), wt_zero = Wt.is_zero();
  auto ns = [&](const BernsteinPoly& X) {
    const BernsteinPoly a = bernstein_product(bernstein_ds(X), W);
    return ws_zero ? a : bernstein_axpy(a, -1.0, bernstein_product(X, Ws));
  };
  auto nt = [&](const BernsteinPoly& X) {
    const BernsteinPoly a = bernstein_product(bernstein_dt(X), W);
    return wt_zero ? a : bernstein_axpy(a, -1.0, bernstein_product(X, Wt));
  };
  auto sum12 = [](Poly12 x, const Poly12& y) {
    for (int k = 0; k < x.size(); ++k) x.c[k] += y.c[k];
    return x;
  };
  auto square12 = [&](const BernsteinPoly& x, const BernsteinPoly& y) {
    const Poly12 x12 = to_poly12(x), y12 = to_poly12(y);
    return elevate12(sum12(product12(x12, x12), product12(y12, y12)));
  };

  std::vector<Patch> leaves;
  leaves.reserve(64);
  leaves.push_back(Patch{ns(xyw[0]), ns(xyw[1]), nt(xyw[0]), nt(xyw[1]), Poly12{}, Poly12{}, Poly12{}});
  // A = 2 D w: the round-off allowance of D (header, "Round-off") times 2 max |w|.
  const double tol_a = 2.0 * kRoundOff * J.scale * W.max_abs_coefficient();
  // w > 0 on the element (a sum of B-splines covering it) is what makes S = X / w a map;
  // a zero scale means D == 0. Neither gives a bound but the trivial one.
  const bool degenerate = !(W.min_coefficient() > 0.0) || !(J.scale > 0.0) || !std::isfinite(J.scale);
  if (!degenerate) bound_patch(leaves.back(), r, tol_a);
  res.patches = 1;

  // Attained values at the corners of a patch (corner coefficients are values;
  // det(N_s, N_t) = D w).
  auto sample_corners = [&](const Patch& p) {
    for (int cj = 0; cj < 2; ++cj)
      for (int ci = 0; ci < 2; ++ci) {
        auto corner = [&](const BernsteinPoly& f) { return f.at(ci * f.m, cj * f.n); };
        const double sx = corner(p.nsx), sy = corner(p.nsy), tx = corner(p.ntx), ty = corner(p.nty);
        const Quality q = quality_at(sx * ty - sy * tx, sx, sy, tx, ty, r);
        const Eigen::Vector2d uv(e.lo.x() + hx * (p.s0 + ci * p.size), e.lo.y() + hy * (p.t0 + cj * p.size));
        if (q.jr < res.mean_ratio.attained) res.mean_ratio.attained = q.jr, res.mean_ratio.attained_at = uv;
        if (q.sj < res.scaled.attained) res.scaled.attained = q.sj, res.scaled.attained_at = uv;
      }
  };
  sample_corners(leaves.front());
  if (!to_gap) {
    res.mean_ratio.lower_bound = leaves[0].jr_lo;
    res.scaled.lower_bound = leaves[0].sj_lo;
    return res;
  }
  auto open = [&](double lo, double attained) {
    return attained - lo > opt.relative_gap * std::abs(attained) + opt.absolute_gap;
  };
  // The cone bound (b) suffices on many elements of fine maps; otherwise make
  // A, S2, T2 (8) once, on the element, for the ratio bound (a).
  if (!degenerate && (open(leaves[0].jr_lo, res.mean_ratio.attained) || open(leaves[0].sj_lo, res.scaled.attained))) {
    Patch& p = leaves[0];
    p.a = elevate12(product12(to_poly12(J.numerator), to_poly12(W)));
    for (int k = 0; k < p.a.size(); ++k) p.a.c[k] *= 2.0;
    p.s2 = square12(p.nsx, p.nsy);
    p.t2 = square12(p.ntx, p.nty);
    p.ratio = true;
    bound_patch(p, r, tol_a);
  }

  bool stuck_jr = degenerate, stuck_sj = degenerate;
  while (true) {
    std::size_t ijr = 0, isj = 0;
    for (std::size_t k = 1; k < leaves.size(); ++k) {
      if (leaves[k].jr_lo < leaves[ijr].jr_lo) ijr = k;
      if (leaves[k].sj_lo < leaves[isj].sj_lo) isj = k;
    }
    const bool need_jr = !stuck_jr && open(leaves[ijr].jr_lo, res.mean_ratio.attained);
    const bool need_sj = !stuck_sj && open(leaves[isj].sj_lo, res.scaled.attained);
    if (!need_jr && !need_sj) break;
    const std::size_t pick = need_jr ? ijr : isj;
    if (leaves[pick].depth >= opt.max_depth) {
      // Splitting any other patch cannot raise the minimum over the patches.
      (need_jr ? stuck_jr : stuck_sj) = true;
      res.converged = false;
      continue;
    }
    if (res.patches + 4 > opt.max_patches) {
      res.converged = false;
      break;
    }
    // De Casteljau on every polynomial: children SW, SE, NW, NE.
    Patch p = std::move(leaves[pick]);
    const auto sx = bernstein_subdivide(p.nsx), sy = bernstein_subdivide(p.nsy);
    const auto tx = bernstein_subdivide(p.ntx), ty = bernstein_subdivide(p.nty);
    std::array<Poly12, 4> a, s2, t2;
    if (p.ratio) a = bernstein_subdivide(p.a), s2 = bernstein_subdivide(p.s2), t2 = bernstein_subdivide(p.t2);
    const double h = 0.5 * p.size;
    for (int q = 0; q < 4; ++q) {
      Patch c{sx[q], sy[q], tx[q], ty[q], a[q], s2[q], t2[q], p.ratio,
              p.depth + 1, p.s0 + (q & 1) * h, p.t0 + (q >> 1) * h, h};
      bound_patch(c, r, tol_a);
      sample_corners(c);
      res.depth = std::max(res.depth, c.depth);
      if (q == 0)
        leaves[pick] = std::move(c);
      else
        leaves.push_back(std::move(c));
    }
    res.patches += 4;
  }
  res.mean_ratio.lower_bound = res.scaled.lower_bound = 1.0;
  for (const Patch& p : leaves) {
    res.mean_ratio.lower_bound = std::min(res.mean_ratio.lower_bound, p.jr_lo);
    res.scaled.lower_bound = std::min(res.scaled.lower_bound, p.sj_lo);
  }
  if (tab.k > 0) dense_sample(xyw, tab, r, e, res);
  return res;
}

// The dense sample of the elements that can hold the map's sampled minimum of
// J_r or SJ, into `per` (the others keep `sampled` = 1, as if sampled above the
// minimum). An element's sampled values are at least its certified lower
// bounds, so an element whose bound exceeds the smallest value sampled so far
// cannot hold the minimum: the elements are sampled in ascending order of
// their bounds until the next bound exceeds it. Every element whose sampled
// value equals the minimum is sampled too (its bound is at most that value),
// so the merge in element order finds the same value, element and point as a
// sample of every element. The first value to beat is the merge's start, 1.
// (A NaN bound is sampled.)
// Returns the number of elements sampled.
std::size_t sample_where_minimum_can_be(const std::vector<BezierElement>& es,
                                        const std::vector<Eigen::Vector2d>& P, const SampleTable& tab,
                                        std::vector<ElementQualityBound>& per) {
  const std::size_t n = per.size();
  auto ascending = [&](auto field) {
    std::vector<std::size_t> order(n);
    for (std::size_t k = 0; k < n; ++k) order[k] = k;
    auto bound = [&](std::size_t k) {
      const double b = (per[k].*field).lower_bound;
      return std::isnan(b) ? -HUGE_VAL : b;
    };
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return bound(a) < bound(b) || (bound(a) == bound(b) && a < b);
    });
    return order;
  };
  const std::vector<std::size_t> by_jr = ascending(&ElementQualityBound::mean_ratio);
  const std::vector<std::size_t> by_sj = ascending(&ElementQualityBound::scaled);
  std::vector<char> sampled(n, 0);
  double least_jr = 1.0, least_sj = 1.0;
  std::size_t i = 0, j = 0, count = 0;
  auto can_hold = [](double bound, double least) { return !(bound > least); };
  for (;;) {
    while (i < n && sampled[by_jr[i]]) ++i;
    while (j < n && sampled[by_sj[j]]) ++j;
    const bool jr = i < n && can_hold(per[by_jr[i]].mean_ratio.lower_bound, least_jr);
    const bool sj = j < n && can_hold(per[by_sj[j]].scaled.lower_bound, least_sj);
    if (!jr && !sj) return count;
    const std::size_t k = jr ? by_jr[i] : by_sj[j];
    sample_element(es[k], P, tab, per[k]);
    sampled[k] = 1;
    ++count;
    least_jr = std::min(least_jr, per[k].mean_ratio.sampled);
    least_sj = std::min(least_sj, per[k].scaled.sampled);
  }
}

// The minimum of each field of b into a (locations and elements follow their
// values). b is one element's (index `first`) or a map's whose element
// indices start at `first` in a's numbering (offset = true).
void merge_into(QualityBound& a, const QualityBound& b, std::size_t first, bool offset) {
  auto index = [&](std::size_t i) { return first + (offset ? i : 0); };
  if (b.lower_bound < a.lower_bound) a.lower_bound = b.lower_bound, a.lower_bound_element = index(b.lower_bound_element);
  if (b.attained < a.attained)
    a.attained = b.attained, a.attained_at = b.attained_at, a.attained_element = index(b.attained_element);
  if (b.sampled < a.sampled)
    a.sampled = b.sampled, a.sampled_at = b.sampled_at, a.sampled_element = index(b.sampled_element);
}

}  // namespace

ElementQualityBound element_quality_bound(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                          const QualityBoundOptions& options) {
  check_options(options);
  return bound_element(e, P, options, SampleTable(options.samples_per_edge));
}

MapQualityBounds certified_map_quality(const TSplineMap& map, const QualityBoundOptions& options) {
  return certified_map_quality(BezierExtraction(map.basis()), map.control_points(), options);
}

MapQualityBounds certified_map_quality(const BezierExtraction& extraction, const std::vector<Eigen::Vector2d>& P,
                                       const QualityBoundOptions& opt) {
  check_options(opt);
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<BezierElement>& es = extraction.elements();
  const SampleTable tab(opt.samples_per_edge);
  std::vector<ElementQualityBound> per(es.size());
  // Elements in chunks of 64 claimed by the threads in turn (per-element work
  // varies with the subdivision); the results are merged in element order, so
  // the figures do not depend on the number of threads.
  constexpr std::size_t kChunk = 64;
  const unsigned hw = detail::hardware_threads();
  const std::size_t threads = std::max<std::size_t>(1, opt.threads > 0 ? opt.threads : hw);
  // Without per-element results, the dense sample is taken afterwards, only
  // where it can hold the map's sampled minimum (sample_where_minimum_can_be),
  // and the bounds are carried to the gap only where they can hold the map's
  // minimum (header, "Over a map").
  const bool sample_all = opt.per_element;
  const SampleTable none(0);
  auto each = [&](const std::vector<std::size_t>* which, bool to_gap) {
    const std::size_t n = which ? which->size() : es.size();
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    std::atomic<std::size_t> next{0};
    auto work = [&] {
      for (std::size_t c; (c = next.fetch_add(1)) < chunks;)
        for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
          const std::size_t k = which ? (*which)[i] : i;
          per[k] = bound_element(es[k], P, opt, sample_all ? tab : none, to_gap);
        }
    };
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < std::min<std::size_t>(threads, chunks); ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
  };
  std::size_t bounded = es.size();
  if (sample_all) {
    each(nullptr, true);
  } else {
    each(nullptr, false);
    double least_jr = 1.0, least_sj = 1.0;  // values of the map (corners of elements)
    for (const ElementQualityBound& b : per) {
      least_jr = std::min(least_jr, b.mean_ratio.attained);
      least_sj = std::min(least_sj, b.scaled.attained);
    }
    std::vector<std::size_t> to_gap;
    for (std::size_t k = 0; k < per.size(); ++k)  // (a NaN bound is carried to the gap)
      if (!(per[k].mean_ratio.lower_bound > least_jr && per[k].scaled.lower_bound > least_sj))
        to_gap.push_back(k);
    bounded = to_gap.size();
    each(&to_gap, true);
  }
  std::size_t sampled_elements = tab.k > 0 ? es.size() : 0;
  if (!sample_all && tab.k > 0) sampled_elements = sample_where_minimum_can_be(es, P, tab, per);

  MapQualityBounds m;
  m.elements = es.size();
  m.bounded_elements = bounded;
  m.sampled_elements = sampled_elements;
  m.samples_per_edge = opt.samples_per_edge;
  m.samples_per_element =
      opt.samples_per_edge > 0 ? static_cast<std::size_t>((opt.samples_per_edge + 1) * (opt.samples_per_edge + 1)) : 0;
  for (std::size_t k = 0; k < per.size(); ++k) {
    const ElementQualityBound& b = per[k];
    merge_into(m.mean_ratio, b.mean_ratio, k, false);
    merge_into(m.scaled, b.scaled, k, false);
    m.max_depth_used = std::max(m.max_depth_used, b.depth);
    m.patches += b.patches;
    if (!b.converged) ++m.elements_not_converged;
  }
  if (opt.per_element) m.per_element = std::move(per);
  m.seconds = toolkit::seconds_since(t0);
  return m;
}

MapQualityBounds certified_map_quality(const std::vector<const TSplineMap*>& maps, const QualityBoundOptions& opt) {
  check_options(opt);
  std::vector<MapQualityBounds> parts;
  parts.reserve(maps.size());
  for (const TSplineMap* map : maps) parts.push_back(certified_map_quality(*map, opt));
  MapQualityBounds m = merge_map_quality(std::move(parts));
  m.samples_per_edge = opt.samples_per_edge;
  return m;
}

MapQualityBounds merge_map_quality(std::vector<MapQualityBounds>&& parts) {
  MapQualityBounds m;
  if (!parts.empty()) m.samples_per_edge = parts.front().samples_per_edge;
  for (MapQualityBounds& b : parts) {
    merge_into(m.mean_ratio, b.mean_ratio, m.elements, true);
    merge_into(m.scaled, b.scaled, m.elements, true);
    m.elements += b.elements;
    m.bounded_elements += b.bounded_elements;
    m.sampled_elements += b.sampled_elements;
    m.samples_per_element = b.samples_per_element;
    m.max_depth_used = std::max(m.max_depth_used, b.max_depth_used);
    m.patches += b.patches;
    m.elements_not_converged += b.elements_not_converged;
    m.seconds += b.seconds;
    for (ElementQualityBound& e : b.per_element) m.per_element.push_back(std::move(e));
  }
  return m;
}

}  // namespace tspline
