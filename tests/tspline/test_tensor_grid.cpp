// Sum factorization of bicubic Bernstein polynomials on tensor grids
// (detail/tensor_grid.h): values and derivatives equal the direct sums at every
// point, and the transpose is the adjoint of the evaluation.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tspline/detail/tensor_grid.h"
#include "tspline/spline/bezier_extraction.h"

namespace {

std::array<double, 4> bernstein3_derivative(double s) {
  const double r = 1.0 - s;
  return {-3.0 * r * r, 3.0 * r * r - 6.0 * s * r, 6.0 * s * r - 3.0 * s * s, 3.0 * s * s};
}

tspline::detail::TensorGrid grid_of(int m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> p(m), w(m, 1.0 / m);
  for (double& v : p) v = u(rng);
  tspline::detail::TensorGrid g;
  g.set(p, w);
  return g;
}

}  // namespace

TEST_SUITE("tensor_grid") {
  TEST_CASE("values and derivatives at the grid points equal the direct Bernstein sums (m = 3, 4, 5, 7, 40)") {
    std::mt19937 rng(3);
    std::normal_distribution<double> n01(0.0, 1.0);
    for (int m : {3, 4, 5, 7, 40}) {
      const tspline::detail::TensorGrid g = grid_of(m, rng);
      REQUIRE(g.size() == static_cast<std::size_t>(m * m));
      double c[16];
      for (double& v : c) v = n01(rng);
      std::vector<double> f(g.size()), fs(g.size()), ft(g.size()), scratch(8 * m);
      tspline::detail::tensor_values(g, c, f.data(), fs.data(), ft.data(), scratch.data());
      double err = 0.0;
      for (int r = 0; r < m; ++r)
        for (int p = 0; p < m; ++p) {
          const double s = g.point[p], t = g.point[r];
          const std::array<double, 4> bs = tspline::bernstein3(s), bt = tspline::bernstein3(t);
          const std::array<double, 4> ds = bernstein3_derivative(s), dt = bernstein3_derivative(t);
          double v = 0, vs = 0, vt = 0;
          for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
              v += c[i + 4 * j] * bs[i] * bt[j];
              vs += c[i + 4 * j] * ds[i] * bt[j];
              vt += c[i + 4 * j] * bs[i] * dt[j];
            }
          const std::size_t q = static_cast<std::size_t>(p + m * r);
          err = std::max({err, std::abs(f[q] - v), std::abs(fs[q] - vs), std::abs(ft[q] - vt)});
        }
      CAPTURE(m);
      CHECK(err < 1e-13);
    }
  }

  TEST_CASE("the transpose is the adjoint: <values(c), (a, as, at)> = <c, transpose(a, as, at)>") {
    std::mt19937 rng(5);
    std::normal_distribution<double> n01(0.0, 1.0);
    for (int m : {4, 5, 10}) {
      const tspline::detail::TensorGrid g = grid_of(m, rng);
      const std::size_t n = g.size();
      double c[16];
      for (double& v : c) v = n01(rng);
      std::vector<double> a(n), as(n), at(n), f(n), fs(n), ft(n), scratch(8 * m);
      for (std::size_t q = 0; q < n; ++q) a[q] = n01(rng), as[q] = n01(rng), at[q] = n01(rng);
      tspline::detail::tensor_values(g, c, f.data(), fs.data(), ft.data(), scratch.data());
      double lhs = 0.0;
      for (std::size_t q = 0; q < n; ++q) lhs += f[q] * a[q] + fs[q] * as[q] + ft[q] * at[q];
      for (bool with_values : {true, false}) {
        double back[16] = {};
        tspline::detail::tensor_values_transpose(g, with_values ? a.data() : nullptr, as.data(), at.data(), back,
                                                 scratch.data());
        double rhs = 0.0;
        for (int i = 0; i < 16; ++i) rhs += c[i] * back[i];
        double expected = lhs;
        if (!with_values)
          for (std::size_t q = 0; q < n; ++q) expected -= f[q] * a[q];
        CAPTURE(m);
        CAPTURE(with_values);
        CHECK(rhs == doctest::Approx(expected).epsilon(1e-12));
      }
    }
  }
}
