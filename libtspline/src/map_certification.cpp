// Certified validity of the T-spline map; see map_certification.h for the method.
#include "tspline/map_certification.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>

#include "tspline/map_quality.h"

namespace tspline {

namespace {

constexpr int kMax = BernsteinPoly::kMaxDegree;

// binom(n, k) for n <= 2 kMax (exact in double).
double binom(int n, int k) {
  static const auto table = [] {
    std::array<std::array<double, 2 * kMax + 1>, 2 * kMax + 1> t{};
    for (int i = 0; i <= 2 * kMax; ++i) {
      t[i][0] = t[i][i] = 1.0;
      for (int j = 1; j < i; ++j) t[i][j] = t[i - 1][j - 1] + t[i - 1][j];
    }
    return t;
  }();
  return table[n][k];
}

// Bernstein basis values B_i^deg(s), i = 0..deg.
void bernstein_values(int deg, double s, double* out) {
  // Powers by repeated multiplication (no pow calls): s^i and r^(deg-i).
  const double r = 1.0 - s;
  double sp[kMax + 1], rp[kMax + 1];
  sp[0] = rp[0] = 1.0;
  for (int i = 1; i <= deg; ++i) sp[i] = sp[i - 1] * s, rp[i] = rp[i - 1] * r;
  for (int i = 0; i <= deg; ++i) out[i] = binom(deg, i) * sp[i] * rp[deg - i];
}

// Gauss-Legendre (5 points on [0,1]) nodes, weights and the Bernstein values of
// degrees 3 and 8 there, for the element mean of det J.
struct GaussBernstein {
  std::vector<double> p, w;
  double b3[5][4], b8[5][9];
};
const GaussBernstein& gauss_bernstein() {
  static const GaussBernstein g = [] {
    GaussBernstein t;
    gauss_points_01(5, t.p, t.w);
    for (int a = 0; a < 5; ++a) {
      bernstein_values(3, t.p[a], t.b3[a]);
      bernstein_values(8, t.p[a], t.b8[a]);
    }
    return t;
  }();
  return g;
}

// p(s_a, t_b) at Gauss nodes a, b from tabulated basis values (bidegree (d, d)).
template <int d>
double at_gauss(const BernsteinPoly& p, const double (&bs)[d + 1], const double (&bt)[d + 1]) {
  double v = 0.0;
  for (int j = 0; j <= d; ++j) {
    double row = 0.0;
    for (int i = 0; i <= d; ++i) row += p.c[i + (d + 1) * j] * bs[i];
    v += row * bt[j];
  }
  return v;
}

// de Casteljau split of one coefficient row (stride `stride`, deg+1 values) at 1/2.
void split_row(const double* in, int deg, int stride, double* left, double* right) {
  double w[kMax + 1];
  for (int i = 0; i <= deg; ++i) w[i] = in[i * stride];
  for (int k = 0; k <= deg; ++k) {
    left[k * stride] = w[0];
    right[(deg - k) * stride] = w[deg - k];
    for (int i = 0; i < deg - k; ++i) w[i] = 0.5 * (w[i] + w[i + 1]);
  }
}

double max_abs(const BernsteinPoly& p) { return p.max_abs_coefficient(); }

}  // namespace

// ---------------------------------------------------------------------------
// Bernstein arithmetic
// ---------------------------------------------------------------------------
BernsteinPoly::BernsteinPoly(int m_, int n_) : m(m_), n(n_) {
  if (m < 0 || n < 0 || m > kMaxDegree || n > kMaxDegree)
    throw std::invalid_argument("BernsteinPoly: bidegree out of range");
}

double BernsteinPoly::min_coefficient() const { return *std::min_element(c.begin(), c.begin() + size()); }

double BernsteinPoly::max_abs_coefficient() const {
  double r = 0.0;
  for (int k = 0; k < size(); ++k) r = std::max(r, std::abs(c[k]));
  return r;
}

double BernsteinPoly::operator()(double s, double t) const {
  double bs[kMax + 1], bt[kMax + 1];
  bernstein_values(m, s, bs);
  bernstein_values(n, t, bt);
  double v = 0.0;
  for (int j = 0; j <= n; ++j) {
    double row = 0.0;
    for (int i = 0; i <= m; ++i) row += at(i, j) * bs[i];
    v += row * bt[j];
  }
  return v;
}

// With scaled coefficients a_ij binom(m1,i) binom(n1,j) the product is a plain
// 2-D convolution (the power-basis identity B_i^m1 B_k^m2 =
// binom(m1,i) binom(m2,k) / binom(m1+m2,i+k) B_{i+k}^{m1+m2}).
BernsteinPoly bernstein_product(const BernsteinPoly& a, const BernsteinPoly& b) {
  BernsteinPoly r(a.m + b.m, a.n + b.n);
  double sa[(kMax + 1) * (kMax + 1)], sb[(kMax + 1) * (kMax + 1)];
  for (int j = 0; j <= a.n; ++j)
    for (int i = 0; i <= a.m; ++i) sa[i + (a.m + 1) * j] = a.at(i, j) * binom(a.m, i) * binom(a.n, j);
  for (int j = 0; j <= b.n; ++j)
    for (int i = 0; i <= b.m; ++i) sb[i + (b.m + 1) * j] = b.at(i, j) * binom(b.m, i) * binom(b.n, j);
  for (int j1 = 0; j1 <= a.n; ++j1)
    for (int i1 = 0; i1 <= a.m; ++i1) {
      const double x = sa[i1 + (a.m + 1) * j1];
      if (x == 0.0) continue;
      for (int j2 = 0; j2 <= b.n; ++j2)
        for (int i2 = 0; i2 <= b.m; ++i2) r.at(i1 + i2, j1 + j2) += x * sb[i2 + (b.m + 1) * j2];
    }
  for (int j = 0; j <= r.n; ++j)
    for (int i = 0; i <= r.m; ++i) r.at(i, j) /= binom(r.m, i) * binom(r.n, j);
  return r;
}

BernsteinPoly bernstein_ds(const BernsteinPoly& a) {
  if (a.m < 1) throw std::invalid_argument("bernstein_ds: degree 0");
  BernsteinPoly r(a.m - 1, a.n);
  for (int j = 0; j <= a.n; ++j)
    for (int i = 0; i < a.m; ++i) r.at(i, j) = a.m * (a.at(i + 1, j) - a.at(i, j));
  return r;
}

BernsteinPoly bernstein_dt(const BernsteinPoly& a) {
  if (a.n < 1) throw std::invalid_argument("bernstein_dt: degree 0");
  BernsteinPoly r(a.m, a.n - 1);
  for (int j = 0; j < a.n; ++j)
    for (int i = 0; i <= a.m; ++i) r.at(i, j) = a.n * (a.at(i, j + 1) - a.at(i, j));
  return r;
}

BernsteinPoly bernstein_axpy(const BernsteinPoly& a, double f, const BernsteinPoly& b) {
  if (a.m != b.m || a.n != b.n) throw std::invalid_argument("bernstein_axpy: bidegrees differ");
  BernsteinPoly r = a;
  for (int k = 0; k < r.size(); ++k) r.c[k] += f * b.c[k];
  return r;
}

std::array<BernsteinPoly, 4> bernstein_subdivide(const BernsteinPoly& p) {
  // Split in s row by row into left/right, then each in t column by column.
  BernsteinPoly ls(p.m, p.n), rs(p.m, p.n);
  for (int j = 0; j <= p.n; ++j)
    split_row(&p.c[(p.m + 1) * j], p.m, 1, &ls.c[(p.m + 1) * j], &rs.c[(p.m + 1) * j]);
  std::array<BernsteinPoly, 4> q = {BernsteinPoly(p.m, p.n), BernsteinPoly(p.m, p.n), BernsteinPoly(p.m, p.n),
                                    BernsteinPoly(p.m, p.n)};
  for (int i = 0; i <= p.m; ++i) {
    split_row(&ls.c[i], p.n, p.m + 1, &q[0].c[i], &q[2].c[i]);
    split_row(&rs.c[i], p.n, p.m + 1, &q[1].c[i], &q[3].c[i]);
  }
  return q;
}

// ---------------------------------------------------------------------------
// The Jacobian numerator of an element
// ---------------------------------------------------------------------------
double ElementJacobian::det_param(const BezierElement& e, double s, double t) const {
  const double w = weight(s, t);
  return numerator(s, t) / (w * w * w * (e.hi.x() - e.lo.x()) * (e.hi.y() - e.lo.y()));
}

ElementJacobian element_jacobian(const BezierElement& e, const std::vector<Eigen::Vector2d>& P) {
  const Eigen::Index nf = e.C.rows();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (Eigen::Index r = 0; r < nf; ++r) centre += P[e.functions[r]];
  if (nf > 0) centre /= static_cast<double>(nf);
  BernsteinPoly X(3, 3), Y(3, 3), W(3, 3);
  for (Eigen::Index r = 0; r < nf; ++r) {
    const Eigen::Vector2d p = P[e.functions[r]] - centre;
    for (int k = 0; k < 16; ++k) {
      const double b = e.C(r, k);
      X.c[k] += p.x() * b;
      Y.c[k] += p.y() * b;
      W.c[k] += b;
    }
  }
  const BernsteinPoly Xs = bernstein_ds(X), Ys = bernstein_ds(Y), Xt = bernstein_dt(X), Yt = bernstein_dt(Y);
  const BernsteinPoly Ws = bernstein_ds(W), Wt = bernstein_dt(W);
  // det(X_s, X_t), det(X_s, X), det(X, X_t)
  const BernsteinPoly d_st = bernstein_axpy(bernstein_product(Xs, Yt), -1.0, bernstein_product(Ys, Xt));
  const BernsteinPoly d_s0 = bernstein_axpy(bernstein_product(Xs, Y), -1.0, bernstein_product(Ys, X));
  const BernsteinPoly d_0t = bernstein_axpy(bernstein_product(X, Yt), -1.0, bernstein_product(Y, Xt));
  ElementJacobian J;
  J.weight = W;
  J.numerator = bernstein_axpy(bernstein_axpy(bernstein_product(W, d_st), -1.0, bernstein_product(Wt, d_s0)),
                               -1.0, bernstein_product(Ws, d_0t));
  // |D| <= the same expression with every factor replaced by its largest
  // absolute coefficient (Bernstein coefficients of a product are convex
  // combinations of products of coefficients).
  const double xs = std::max(max_abs(Xs), max_abs(Ys)), xt = std::max(max_abs(Xt), max_abs(Yt));
  const double x0 = std::max(max_abs(X), max_abs(Y));
  J.scale = 2.0 * (max_abs(W) * xs * xt + max_abs(Wt) * xs * x0 + max_abs(Ws) * x0 * xt);
  return J;
}

// ---------------------------------------------------------------------------
// Certification of one element
// ---------------------------------------------------------------------------
ElementCertificate certify_element(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                   const CertificationOptions& opt) {
  if (opt.max_depth < 0 || opt.max_depth > 20)
    throw std::invalid_argument("certify_element: max_depth out of range");
  const ElementJacobian J = element_jacobian(e, P);
  const double area = (e.hi.x() - e.lo.x()) * (e.hi.y() - e.lo.y());
  const double tol = opt.relative_tolerance * J.scale;
  const double w_min = J.weight.min_coefficient(), w_max = J.weight.max_abs_coefficient();
  ElementCertificate cert;

  // Mean of det J over the element: 5x5 Gauss (exact for D when w is constant).
  {
    const GaussBernstein& g = gauss_bernstein();
    double sum = 0.0;
    for (int a = 0; a < 5; ++a)
      for (int b = 0; b < 5; ++b) {
        const double w = at_gauss<3>(J.weight, g.b3[a], g.b3[b]);
        sum += g.w[a] * g.w[b] * at_gauss<8>(J.numerator, g.b8[a], g.b8[b]) / (w * w * w);
      }
    cert.det_mean = sum / area;
  }

  // Rigorous bound of D / w^3 from a lower bound d of D on a region.
  auto bound = [&](double d) {
    if (d >= 0.0) return d / (w_max * w_max * w_max);
    return w_min > 0.0 ? d / (w_min * w_min * w_min) : -std::numeric_limits<double>::infinity();
  };
  auto finish = [&](double d_low) {
    cert.det_lower_bound = bound(d_low) / area;
    cert.relative_lower_bound =
        cert.det_mean > 0.0 ? cert.det_lower_bound / cert.det_mean : -std::numeric_limits<double>::infinity();
    return cert;
  };

  const double d_root = J.numerator.min_coefficient();
  if (!(w_min > 0.0) || !(J.scale > 0.0) || !std::isfinite(J.scale)) {
    // w must be positive (it is a sum of B-splines covering the element); a
    // zero scale means D == 0 (a collapsed element). Neither can be certified.
    cert.status = ElementStatus::Undecided;
    return finish(std::min(d_root, 0.0));
  }

  struct Patch {
    BernsteinPoly d;
    int depth;
    double s0, t0, size;
  };
  std::deque<Patch> queue;  // breadth first: coarse corner samples first
  queue.push_back({J.numerator, 0, 0.0, 0.0, 1.0});
  double d_low = std::numeric_limits<double>::infinity();
  bool undecided = false;
  constexpr std::size_t kMaxPatches = 4096;  // bound on work for degenerate elements
  const int m = J.numerator.m, n = J.numerator.n;
  while (!queue.empty()) {
    Patch p = std::move(queue.front());
    queue.pop_front();
    ++cert.patches;
    cert.depth = std::max(cert.depth, p.depth);
    const double dmin = p.d.min_coefficient();
    if (dmin > tol) {
      d_low = std::min(d_low, dmin);
      continue;
    }
    // Corner coefficients are values: a negative one is a counterexample.
    const std::array<std::array<int, 2>, 4> corners = {{{0, 0}, {m, 0}, {0, n}, {m, n}}};
    for (const auto& [i, j] : corners) {
      const double v = p.d.at(i, j);
      if (v < -tol) {
        const double s = p.s0 + p.size * i / m, t = p.t0 + p.size * j / n;
        cert.status = ElementStatus::Invalid;
        cert.negative_at = {e.lo.x() + s * (e.hi.x() - e.lo.x()), e.lo.y() + t * (e.hi.y() - e.lo.y())};
        const double w = J.weight(s, t);
        cert.negative_det = v / (w * w * w * area);
        return finish(d_root);  // the search is incomplete: fall back to the root coefficients
      }
    }
    if (p.depth >= opt.max_depth || cert.patches + queue.size() >= kMaxPatches) {
      undecided = true;
      d_low = std::min(d_low, dmin);
      continue;
    }
    const std::array<BernsteinPoly, 4> q = bernstein_subdivide(p.d);
    const double h = 0.5 * p.size;
    queue.push_back({q[0], p.depth + 1, p.s0, p.t0, h});
    queue.push_back({q[1], p.depth + 1, p.s0 + h, p.t0, h});
    queue.push_back({q[2], p.depth + 1, p.s0, p.t0 + h, h});
    queue.push_back({q[3], p.depth + 1, p.s0 + h, p.t0 + h, h});
  }
  cert.status = undecided ? ElementStatus::Undecided : ElementStatus::Certified;
  return finish(d_low);
}

// ---------------------------------------------------------------------------
// The whole map
// ---------------------------------------------------------------------------
MapCertification certify_map(const TSplineMap& map, const CertificationOptions& opt) {
  return certify_map(BezierExtraction(map.basis()), map.mesh().num_cells(), map.control_points(), opt);
}

MapCertification certify_map(const BezierExtraction& extraction, std::size_t num_cells,
                             const std::vector<Eigen::Vector2d>& P, const CertificationOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  MapCertification r;
  r.cell_certified.assign(num_cells, 1);
  r.min_relative_lower_bound = std::numeric_limits<double>::infinity();
  r.min_det_lower_bound = std::numeric_limits<double>::infinity();
  const std::vector<BezierElement>& es = extraction.elements();
  for (std::size_t k = 0; k < es.size(); ++k) {
    const BezierElement& e = es[k];
    const ElementCertificate cert = certify_element(e, P, opt);
    ++r.elements;
    r.max_depth_used = std::max(r.max_depth_used, cert.depth);
    r.min_relative_lower_bound = std::min(r.min_relative_lower_bound, cert.relative_lower_bound);
    r.min_det_lower_bound = std::min(r.min_det_lower_bound, cert.det_lower_bound);
    switch (cert.status) {
      case ElementStatus::Certified:
        ++r.certified;
        continue;
      case ElementStatus::Invalid:
        ++r.invalid;
        break;
      case ElementStatus::Undecided:
        ++r.undecided;
        break;
    }
    r.cell_certified[e.cell] = 0;
    r.failures.push_back({e.cell, k, e.lo, e.hi, cert});
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace tspline
