// Cubic hierarchical B-splines on quadtree T-meshes (the Poisson analysis space):
// tensor-product B-splines on uniform meshes, cubic polynomial reproduction and
// nestedness on T-meshes (where the normalized T-spline functions fail),
// linear independence, support lists, border functions, derivatives.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <set>

#include "test_support.h"
#include "tspline/analysis/hierarchical_basis.h"
#include "tspline/analysis/poisson.h"
#include "tspline/spline/tspline_basis.h"

using tspline::BasisValues;
using tspline::HierarchicalBasis;
using tspline::TMesh;

namespace {

/// Sample points: k x k interior points per cell, with their cells.
struct Samples {
  std::vector<Eigen::Vector2d> uv;
  std::vector<int> cell;
};
Samples cell_samples(const TMesh& m, int k) {
  Samples s;
  for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) {
    const Eigen::Vector2d lo = m.cell_min(c), len = m.cell_max(c) - lo;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        s.uv.push_back(lo + Eigen::Vector2d((i + 0.37) / k * len.x(), (j + 0.61) / k * len.y()));
        s.cell.push_back(c);
      }
  }
  return s;
}

/// Collocation matrix A(p, a) = basis function a at sample p (located in the basis's own mesh).
template <class Basis>
Eigen::MatrixXd collocation(const Basis& b, const Samples& s) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(s.uv.size()), static_cast<Eigen::Index>(b.size()));
  BasisValues bv;
  for (std::size_t p = 0; p < s.uv.size(); ++p) {
    b.evaluate(b.locate(s.uv[p]), s.uv[p], bv, 0);  // the samples may come from another mesh
    for (std::size_t k = 0; k < bv.ids.size(); ++k) A(static_cast<Eigen::Index>(p), bv.ids[k]) = bv.R[k];
  }
  return A;
}

/// Max residual of the least-squares fit of the values y by the columns of A.
double fit_residual(const Eigen::MatrixXd& A, const Eigen::VectorXd& y) {
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(y);
  return (A * c - y).cwiseAbs().maxCoeff();
}

}  // namespace

TEST_SUITE("hierarchical_basis") {
  TEST_CASE("uniform meshes: the tensor-product open-knot B-splines") {
    for (int level = 0; level <= 3; ++level) {
      TMesh m(level);
      m.build_topology();
      const HierarchicalBasis hb(m);
      const std::size_t n = (std::size_t{1} << level) + 3;
      CHECK(hb.size() == n * n);
      // The same functions as the T-spline basis of a mesh without T-junctions.
      const tspline::TSplineBasis tb(m);
      REQUIRE(tb.size() == hb.size());
      std::set<std::pair<std::array<double, 5>, std::array<double, 5>>> tk, hk;
      for (const auto& f : tb.functions()) tk.insert({f.knots_xi, f.knots_eta});
      for (std::size_t a = 0; a < hb.size(); ++a) {
        const auto& f = hb.function(static_cast<int>(a));
        CHECK(f.level == level);
        hk.insert({f.knots_xi, f.knots_eta});
      }
      CHECK(tk == hk);
      for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) CHECK(hb.functions_on_cell(c).size() == 16);
    }
  }

  TEST_CASE("T-meshes: every cubic polynomial is reproduced, the normalized T-spline basis fails") {
    for (unsigned seed : {3u, 11u}) {
      const TMesh m = test_support::random_tmesh(seed, 25, 6);
      REQUIRE(m.num_hanging_vertices() > 0);
      const Samples s = cell_samples(m, 5);
      const Eigen::MatrixXd A = collocation(HierarchicalBasis(m), s);
      const Eigen::MatrixXd T = collocation(tspline::TSplineBasis(m), s);
      double worst = 0.0;
      for (int a = 0; a <= 3; ++a)
        for (int b = 0; b <= 3; ++b) {
          Eigen::VectorXd y(static_cast<Eigen::Index>(s.uv.size()));
          for (std::size_t p = 0; p < s.uv.size(); ++p)
            y[static_cast<Eigen::Index>(p)] = std::pow(s.uv[p].x(), a) * std::pow(s.uv[p].y(), b);
          worst = std::max(worst, fit_residual(A, y));
        }
      Eigen::VectorXd x(static_cast<Eigen::Index>(s.uv.size()));
      for (std::size_t p = 0; p < s.uv.size(); ++p) x[static_cast<Eigen::Index>(p)] = s.uv[p].x();
      const double tspline_x = fit_residual(T, x);
      MESSAGE("seed " << seed << ": " << m.num_cells() << " cells, " << m.num_hanging_vertices()
                      << " hanging vertices; max LSQ residual of x^a y^b (a, b <= 3): hierarchical " << worst
                      << "; of x with the normalized T-spline basis: " << tspline_x);
      CHECK(worst <= 1e-12);
      CHECK(tspline_x >= 1e-6);
    }
  }

  TEST_CASE("linear independence: the Gram matrix is positive definite") {
    const TMesh m = test_support::random_tmesh(5, 30, 6);
    const HierarchicalBasis hb(m);
    const Samples s = cell_samples(m, 5);  // 25 points per cell >= 16 polynomial coefficients
    const Eigen::MatrixXd A = collocation(hb, s);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
    const auto& sv = svd.singularValues();
    MESSAGE(hb.size() << " functions on " << m.num_cells() << " cells: singular values " << sv[0] << " .. "
                      << sv[sv.size() - 1]);
    CHECK(sv[sv.size() - 1] > 1e-6 * sv[0]);
  }

  TEST_CASE("nested: the coarse space lies in the space of a refinement") {
    const TMesh coarse = test_support::random_tmesh(8, 20, 5);
    const TMesh fine = tspline::refine_cells(coarse, {0, 3, static_cast<int>(coarse.num_cells()) - 1});
    const Samples s = cell_samples(fine, 5);
    const Eigen::MatrixXd Ac = collocation(HierarchicalBasis(coarse), s);
    const Eigen::MatrixXd Af = collocation(HierarchicalBasis(fine), s);
    const auto qr = Af.colPivHouseholderQr();
    double worst = 0.0;
    for (Eigen::Index a = 0; a < Ac.cols(); ++a)
      worst = std::max(worst, (Af * qr.solve(Ac.col(a)) - Ac.col(a)).cwiseAbs().maxCoeff());
    MESSAGE("coarse functions in the fine space: max residual " << worst);
    CHECK(worst <= 1e-12);
  }

  TEST_CASE("support lists, border functions and derivatives") {
    const TMesh m = test_support::random_tmesh(13, 40, 7);
    const HierarchicalBasis hb(m);
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    BasisValues bv, bp, bm;
    // Every active function is non-zero exactly on the cells that list it:
    // evaluating ALL functions at a point of cell c gives zero outside the list.
    std::vector<int> listed(hb.size());
    for (int trial = 0; trial < 300; ++trial) {
      const Eigen::Vector2d uv(u01(rng), u01(rng));
      const int c = hb.locate(uv);
      std::fill(listed.begin(), listed.end(), 0);
      for (int a : hb.functions_on_cell(c)) listed[a] = 1;
      for (std::size_t a = 0; a < hb.size(); ++a) {
        const auto& f = hb.function(static_cast<int>(a));
        const double v = tspline::cubic_bspline(f.knots_xi, uv.x()) * tspline::cubic_bspline(f.knots_eta, uv.y());
        if (!listed[a]) CHECK(v == 0.0);
      }
      // First and second derivatives against central differences with step
      // h = 1e-3 w (w the cell width; the functions on the cell have knot spans
      // >= w, so the k-th derivative scales like w^-k): truncation error
      // ~ h^2 |N^(3)| / 6 ~ 2e-7 / w (first) and / w^2 (second); round-off ~ eps / h.
      const Eigen::Vector2d lo = m.cell_min(c), hi = m.cell_max(c);
      const double w = hi.x() - lo.x();
      const double h = 1e-3 * w;
      const Eigen::Vector2d p = lo + (hi - lo).cwiseProduct(Eigen::Vector2d(0.2 + 0.6 * u01(rng), 0.2 + 0.6 * u01(rng)));
      hb.evaluate(c, p, bv, 2);
      for (int dir = 0; dir < 2; ++dir) {
        const Eigen::Vector2d e = dir == 0 ? Eigen::Vector2d(h, 0) : Eigen::Vector2d(0, h);
        hb.evaluate(c, p + e, bp, 2);
        hb.evaluate(c, p - e, bm, 2);
        for (std::size_t k = 0; k < bv.ids.size(); ++k) {
          const double d1 = (dir == 0 ? bv.R_xi[k] : bv.R_eta[k]);
          const double fd1 = (bp.R[k] - bm.R[k]) / (2 * h);
          CHECK(std::abs(d1 - fd1) <= 1e-5 / w);
          const double d2 = dir == 0 ? bv.R_xixi[k] : bv.R_etaeta[k];
          const double fd2 = ((dir == 0 ? bp.R_xi[k] : bp.R_eta[k]) - (dir == 0 ? bm.R_xi[k] : bm.R_eta[k])) / (2 * h);
          CHECK(std::abs(d2 - fd2) <= 1e-5 / (w * w));
          const double dxy = bv.R_xieta[k];
          const double fdxy = dir == 0 ? (bp.R_eta[k] - bm.R_eta[k]) / (2 * h) : (bp.R_xi[k] - bm.R_xi[k]) / (2 * h);
          CHECK(std::abs(dxy - fdxy) <= 1e-5 / (w * w));
        }
      }
    }
    // on_border <=> non-zero somewhere on the border of [0,1]^2.
    std::vector<int> seen(hb.size(), 0);
    for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) {
      const Eigen::Vector2d lo = m.cell_min(c), hi = m.cell_max(c);
      std::vector<Eigen::Vector2d> pts;
      for (double t : {0.3, 0.7}) {
        const Eigen::Vector2d q = lo + t * (hi - lo);
        if (lo.x() == 0.0) pts.emplace_back(0.0, q.y());
        if (hi.x() == 1.0) pts.emplace_back(1.0, q.y());
        if (lo.y() == 0.0) pts.emplace_back(q.x(), 0.0);
        if (hi.y() == 1.0) pts.emplace_back(q.x(), 1.0);
      }
      for (const auto& q : pts) {
        hb.evaluate(c, q, bv, 0);
        for (std::size_t k = 0; k < bv.ids.size(); ++k)
          if (bv.R[k] != 0.0) seen[bv.ids[k]] = 1;
      }
    }
    int border = 0;
    for (std::size_t a = 0; a < hb.size(); ++a) {
      CHECK(hb.function(static_cast<int>(a)).on_border == static_cast<bool>(seen[a]));
      border += seen[a];
    }
    CHECK(border > 0);
  }
}
