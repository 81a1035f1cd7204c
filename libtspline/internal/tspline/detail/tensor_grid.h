#pragma once
// Internal to libtspline: a bicubic polynomial in tensor-product Bernstein
// form (coefficient c[i + 4 j] of B_i(s) B_j(t), as in bezier_extraction.h)
// and its first derivatives at every point of a tensor grid of m x m points
// on [0,1]^2, by sum factorization: first along s (4 rows x m points), then
// along t, 12 m^2 + 32 m multiply-adds for f, f_s and f_t at the m^2 points
// instead of 48 m^2 point by point. The transpose (the adjoint: from values
// at the points back to the 16 coefficients) costs the same. The map's energy
// (map_energy.h) evaluates the map's Jacobian at 25 to 1,600 samples per
// Bezier element this way.
#include <cstddef>
#include <vector>

namespace tspline::detail {

/// The same m abscissae in s and in t; point q = p + m r is (point[p], point[r]).
struct TensorGrid {
  int m = 0;
  std::vector<double> point;   ///< m abscissae in [0, 1]
  std::vector<double> weight;  ///< m weights (the point's weight is weight[p] weight[r])
  std::vector<double> b, db;   ///< 4 m: b[4 p + i] = B_i(point[p]), db its derivative
  std::size_t size() const { return static_cast<std::size_t>(m) * static_cast<std::size_t>(m); }
  /// Sets point and weight, and b, db from them.
  void set(std::vector<double> points, std::vector<double> weights);
};

/// f, f_s, f_t (m^2 values each) of sum c[i + 4 j] B_i(s) B_j(t) at the grid's
/// points. `scratch` holds 8 m values.
void tensor_values(const TensorGrid& g, const double* c, double* f, double* fs, double* ft, double* scratch);

/// The transpose of tensor_values: c[i + 4 j] += sum_q a[q] B_ij(q) + as[q] d_s B_ij(q) + at[q] d_t B_ij(q);
/// a may be null (then taken as 0). `scratch` holds 8 m values.
void tensor_values_transpose(const TensorGrid& g, const double* a, const double* as, const double* at, double* c,
                             double* scratch);

// The same, inline for callers compiled for other instruction sets (map_energy.cpp).
// M > 0: the grid has M points per direction (loops of known length, unrolled); M = 0: g.m.
template <int M>
inline void tensor_values_fixed(const TensorGrid& g, const double* __restrict c, double* __restrict f, double* __restrict fs,
            double* __restrict ft, double* __restrict scratch) {
  const int m = M > 0 ? M : g.m;
  const double* b = g.b.data();
  const double* db = g.db.data();
  // Along s: T0[j][p] = sum_i c[i + 4 j] B_i(s_p), T1 with B_i'.
  double* T0 = scratch;
  double* T1 = scratch + 4 * m;
  for (int j = 0; j < 4; ++j) {
    const double c0 = c[4 * j], c1 = c[4 * j + 1], c2 = c[4 * j + 2], c3 = c[4 * j + 3];
    for (int p = 0; p < m; ++p) {
      const double* bp = b + 4 * p;
      const double* dp = db + 4 * p;
      T0[j * m + p] = c0 * bp[0] + c1 * bp[1] + c2 * bp[2] + c3 * bp[3];
      T1[j * m + p] = c0 * dp[0] + c1 * dp[1] + c2 * dp[2] + c3 * dp[3];
    }
  }
  // Along t.
  const double* T00 = T0;
  const double* T01 = T0 + m;
  const double* T02 = T0 + 2 * m;
  const double* T03 = T0 + 3 * m;
  const double* T10 = T1;
  const double* T11 = T1 + m;
  const double* T12 = T1 + 2 * m;
  const double* T13 = T1 + 3 * m;
  for (int r = 0; r < m; ++r) {
    const double b0 = b[4 * r], b1 = b[4 * r + 1], b2 = b[4 * r + 2], b3 = b[4 * r + 3];
    const double d0 = db[4 * r], d1 = db[4 * r + 1], d2 = db[4 * r + 2], d3 = db[4 * r + 3];
    double* fr = f + static_cast<std::ptrdiff_t>(m) * r;
    double* fsr = fs + static_cast<std::ptrdiff_t>(m) * r;
    double* ftr = ft + static_cast<std::ptrdiff_t>(m) * r;
    for (int p = 0; p < m; ++p) {
      fr[p] = T00[p] * b0 + T01[p] * b1 + T02[p] * b2 + T03[p] * b3;
      fsr[p] = T10[p] * b0 + T11[p] * b1 + T12[p] * b2 + T13[p] * b3;
      ftr[p] = T00[p] * d0 + T01[p] * d1 + T02[p] * d2 + T03[p] * d3;
    }
  }
}

template <int M>
inline void tensor_values_transpose_fixed(const TensorGrid& g, const double* __restrict a, const double* __restrict as,
                      const double* __restrict at, double* __restrict c, double* __restrict scratch) {
  const int m = M > 0 ? M : g.m;
  const double* b = g.b.data();
  const double* db = g.db.data();
  // Along t: U0[j][p] = sum_r a B_j(t_r) + at B_j'(t_r), U1[j][p] = sum_r as B_j(t_r).
  double* U0 = scratch;
  double* U1 = scratch + 4 * m;
  for (int k = 0; k < 8 * m; ++k) scratch[k] = 0.0;
  for (int r = 0; r < m; ++r) {
    const double* ar = a ? a + static_cast<std::ptrdiff_t>(m) * r : nullptr;
    const double* asr = as + static_cast<std::ptrdiff_t>(m) * r;
    const double* atr = at + static_cast<std::ptrdiff_t>(m) * r;
    for (int j = 0; j < 4; ++j) {
      const double bj = b[4 * r + j], dj = db[4 * r + j];
      double* u0 = U0 + j * m;
      double* u1 = U1 + j * m;
      if (ar)
        for (int p = 0; p < m; ++p) u0[p] += ar[p] * bj + atr[p] * dj;
      else
        for (int p = 0; p < m; ++p) u0[p] += atr[p] * dj;
      for (int p = 0; p < m; ++p) u1[p] += asr[p] * bj;
    }
  }
  // Along s.
  for (int j = 0; j < 4; ++j) {
    double acc[4] = {0.0, 0.0, 0.0, 0.0};
    const double* u0 = U0 + j * m;
    const double* u1 = U1 + j * m;
    for (int p = 0; p < m; ++p)
      for (int i = 0; i < 4; ++i) acc[i] += u0[p] * b[4 * p + i] + u1[p] * db[4 * p + i];
    for (int i = 0; i < 4; ++i) c[i + 4 * j] += acc[i];
  }
}


}  // namespace tspline::detail
