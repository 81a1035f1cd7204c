// Bernstein arithmetic on [0,1]^2; see tspline/detail/bernstein.h.
#include "tspline/detail/bernstein.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include "toolkit/errors.h"

namespace tspline::detail {

namespace {

constexpr int kMax = BernsteinPoly::kMaxDegree;

static_assert(2 * kMax <= kMaxBinomial, "products of Bernstein polynomials need C(2 kMax, k)");
static_assert(kMax <= kMaxSplitDegree, "bernstein_subdivide splits rows of up to kMaxSplitDegree + 1 values");

}  // namespace

// Bernstein basis values B_i^deg(s), i = 0..deg.
void bernstein_values(int deg, double s, double* out) {
  // Powers by repeated multiplication (no pow calls): s^i and r^(deg-i).
  const double r = 1.0 - s;
  double sp[kMax + 1], rp[kMax + 1];
  sp[0] = rp[0] = 1.0;
  for (int i = 1; i <= deg; ++i) sp[i] = sp[i - 1] * s, rp[i] = rp[i - 1] * r;
  for (int i = 0; i <= deg; ++i) out[i] = binomial(deg, i) * sp[i] * rp[deg - i];
}

void bernstein_split_half(const double* in, int deg, int stride, double* left, double* right) {
  double w[kMaxSplitDegree + 1];
  for (int i = 0; i <= deg; ++i) w[i] = in[i * stride];
  for (int k = 0; k <= deg; ++k) {
    left[k * stride] = w[0];
    right[(deg - k) * stride] = w[deg - k];
    for (int i = 0; i < deg - k; ++i) w[i] = 0.5 * (w[i] + w[i + 1]);
  }
}

// ---------------------------------------------------------------------------
// Bernstein arithmetic
// ---------------------------------------------------------------------------
BernsteinPoly::BernsteinPoly(int m_, int n_) : m(m_), n(n_) {
  if (m < 0 || n < 0 || m > kMaxDegree || n > kMaxDegree)
    throw toolkit::InternalError("BernsteinPoly: bidegree out of range");
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

// With scaled coefficients a_ij binomial(m1,i) binomial(n1,j) the product is a plain
// 2-D convolution (the power-basis identity B_i^m1 B_k^m2 =
// binomial(m1,i) binomial(m2,k) / binomial(m1+m2,i+k) B_{i+k}^{m1+m2}).
bool BernsteinPoly::is_zero() const {
  for (int k = 0; k < size(); ++k)
    if (c[k] != 0.0) return false;
  return true;
}

BernsteinPoly bernstein_product(const BernsteinPoly& a, const BernsteinPoly& b) {
  BernsteinPoly r(a.m + b.m, a.n + b.n);
  double sa[(kMax + 1) * (kMax + 1)], sb[(kMax + 1) * (kMax + 1)];
  for (int j = 0; j <= a.n; ++j)
    for (int i = 0; i <= a.m; ++i) sa[i + (a.m + 1) * j] = a.at(i, j) * binomial(a.m, i) * binomial(a.n, j);
  for (int j = 0; j <= b.n; ++j)
    for (int i = 0; i <= b.m; ++i) sb[i + (b.m + 1) * j] = b.at(i, j) * binomial(b.m, i) * binomial(b.n, j);
  for (int j1 = 0; j1 <= a.n; ++j1)
    for (int i1 = 0; i1 <= a.m; ++i1) {
      const double x = sa[i1 + (a.m + 1) * j1];
      if (x == 0.0) continue;
      for (int j2 = 0; j2 <= b.n; ++j2)
        for (int i2 = 0; i2 <= b.m; ++i2) r.at(i1 + i2, j1 + j2) += x * sb[i2 + (b.m + 1) * j2];
    }
  for (int j = 0; j <= r.n; ++j)
    for (int i = 0; i <= r.m; ++i) r.at(i, j) /= binomial(r.m, i) * binomial(r.n, j);
  return r;
}

BernsteinPoly bernstein_ds(const BernsteinPoly& a) {
  if (a.m < 1) throw toolkit::InternalError("bernstein_ds: degree 0");
  BernsteinPoly r(a.m - 1, a.n);
  for (int j = 0; j <= a.n; ++j)
    for (int i = 0; i < a.m; ++i) r.at(i, j) = a.m * (a.at(i + 1, j) - a.at(i, j));
  return r;
}

BernsteinPoly bernstein_dt(const BernsteinPoly& a) {
  if (a.n < 1) throw toolkit::InternalError("bernstein_dt: degree 0");
  BernsteinPoly r(a.m, a.n - 1);
  for (int j = 0; j < a.n; ++j)
    for (int i = 0; i <= a.m; ++i) r.at(i, j) = a.n * (a.at(i, j + 1) - a.at(i, j));
  return r;
}

BernsteinPoly bernstein_axpy(const BernsteinPoly& a, double f, const BernsteinPoly& b) {
  if (a.m != b.m || a.n != b.n) throw toolkit::InternalError("bernstein_axpy: bidegrees differ");
  BernsteinPoly r = a;
  for (int k = 0; k < r.size(); ++k) r.c[k] += f * b.c[k];
  return r;
}

}  // namespace tspline::detail
