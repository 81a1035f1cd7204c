#pragma once
// Internal to libtspline: polynomials on [0,1]^2 in the tensor-product
// Bernstein basis and their exact arithmetic (product, derivatives, de
// Casteljau subdivision), for the certification of det J > 0
// (validity/map_certification.h). Not part of the public interface.
#include <array>

namespace tspline::detail {

/// A polynomial of bidegree (m, n) <= (8, 8) on [0,1]^2 in the Bernstein basis:
/// p(s, t) = sum_{i<=m, j<=n} c[i + (m+1) j] B_i^m(s) B_j^n(t).
struct BernsteinPoly {
  static constexpr int kMaxDegree = 8;
  int m = 0, n = 0;
  std::array<double, (kMaxDegree + 1) * (kMaxDegree + 1)> c{};

  BernsteinPoly() = default;
  BernsteinPoly(int m_, int n_);
  int size() const { return (m + 1) * (n + 1); }
  double& at(int i, int j) { return c[i + (m + 1) * j]; }
  double at(int i, int j) const { return c[i + (m + 1) * j]; }
  double min_coefficient() const;
  double max_abs_coefficient() const;
  /// Every coefficient is 0 (+0 or -0).
  bool is_zero() const;
  /// Direct evaluation (sum of coefficients times basis values).
  double operator()(double s, double t) const;
};

/// Product: (m1+m2, n1+n2), c_ij = sum a_{i1 j1} b_{i2 j2} binom(m1,i1) binom(m2,i2) / binom(m,i) (same in
/// j).
BernsteinPoly bernstein_product(const BernsteinPoly& a, const BernsteinPoly& b);
/// d/ds (degree m-1 in s): m (c_{i+1,j} - c_{i,j}). Requires m >= 1.
BernsteinPoly bernstein_ds(const BernsteinPoly& a);
/// d/dt (degree n-1 in t). Requires n >= 1.
BernsteinPoly bernstein_dt(const BernsteinPoly& a);
/// a + f b, same bidegree.
BernsteinPoly bernstein_axpy(const BernsteinPoly& a, double f, const BernsteinPoly& b);
/// de Casteljau split at 1/2 of the deg + 1 values in[0], in[stride], ...
/// (deg <= kMaxSplitDegree) into the coefficients of the left and right halves,
/// written with the same stride.
inline constexpr int kMaxSplitDegree = 24;
void bernstein_split_half(const double* in, int deg, int stride, double* left, double* right);

/// The four quarters of [0,1]^2 split at s = t = 1/2 (de Casteljau), each
/// re-parameterized on [0,1]^2: SW, SE, NW, NE. `Poly` is BernsteinPoly or any
/// type with its layout (bidegree m, n; coefficients c[i + (m+1) j]; a
/// constructor Poly(m, n)), such as the bidegree-(12, 12) polynomials of the
/// quality bounds.
template <class Poly>
std::array<Poly, 4> bernstein_subdivide(const Poly& p) {
  // Split in s row by row into left/right, then each in t column by column.
  Poly ls(p.m, p.n), rs(p.m, p.n);
  for (int j = 0; j <= p.n; ++j)
    bernstein_split_half(&p.c[(p.m + 1) * j], p.m, 1, &ls.c[(p.m + 1) * j], &rs.c[(p.m + 1) * j]);
  std::array<Poly, 4> q = {Poly(p.m, p.n), Poly(p.m, p.n), Poly(p.m, p.n), Poly(p.m, p.n)};
  for (int i = 0; i <= p.m; ++i) {
    bernstein_split_half(&ls.c[i], p.n, p.m + 1, &q[0].c[i], &q[2].c[i]);
    bernstein_split_half(&rs.c[i], p.n, p.m + 1, &q[1].c[i], &q[3].c[i]);
  }
  return q;
}

/// The Bernstein basis values B_i^deg(s), i = 0..deg (deg <= BernsteinPoly::kMaxDegree), into out[0..deg].
void bernstein_values(int deg, double s, double* out);

/// The binomial coefficient C(n, k), 0 <= k <= n <= kMaxBinomial, from a table
/// (every such C(n, k) is below 2^53, so exact in double).
inline constexpr int kMaxBinomial = 24;
/// Pascal's triangle, made at compile time (inline lookups in the Bernstein
/// products of the certification, the hottest loop after the energy's).
inline constexpr auto kBinomials = [] {
  std::array<std::array<double, kMaxBinomial + 1>, kMaxBinomial + 1> t{};
  for (int i = 0; i <= kMaxBinomial; ++i) {
    t[i][0] = t[i][i] = 1.0;
    for (int j = 1; j < i; ++j) t[i][j] = t[i - 1][j - 1] + t[i - 1][j];
  }
  return t;
}();
inline double binomial(int n, int k) { return kBinomials[n][k]; }

}  // namespace tspline::detail
