// Bezier extraction of the T-spline basis: the elements tile each cell, and the
// Bernstein form reproduces every blending function N_a and the map S at random
// points to round-off, on uniform meshes and on T-meshes with hanging vertices.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "test_support.h"
#include "tspline/detail/quadrature.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/element_map.h"
#include "tspline/validity/map_quality.h"
#include "tspline/tmesh/tmesh.h"
#include "tspline/spline/tspline_map.h"

using tspline::BezierElement;
using tspline::TMesh;
using tspline::TSplineBasis;
using tspline::TSplineMap;

namespace {


// sum_k C(r, k) B_k(s, t)
double bernstein_value(const BezierElement& e, int r, const Eigen::Vector2d& st) {
  const std::array<double, 4> bs = tspline::bernstein3(st.x()), bt = tspline::bernstein3(st.y());
  double v = 0.0;
  for (int q = 0; q < 4; ++q)
    for (int p = 0; p < 4; ++p) v += e.C(r, p + 4 * q) * bs[p] * bt[q];
  return v;
}

double direct_value(const tspline::BlendingFunction& f, const Eigen::Vector2d& uv) {
  return tspline::cubic_bspline(f.knots_xi, uv.x()) * tspline::cubic_bspline(f.knots_eta, uv.y());
}

// Checks the extraction of every cell of `basis` at `samples` random points per
// element against direct evaluation; returns the number of cells with > 1 element.
int check_extraction(const TSplineMap& map, int samples, unsigned seed) {
  const TSplineBasis& basis = map.basis();
  const TMesh& mesh = map.mesh();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int split_cells = 0;
  double max_err_n = 0.0, max_err_s = 0.0;
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    const std::vector<BezierElement> es = tspline::extract_cell(basis, c);
    REQUIRE(!es.empty());
    if (es.size() > 1) ++split_cells;
    // The elements tile the cell: inside it, and areas add up (exact dyadics).
    double area = 0.0;
    for (const BezierElement& e : es) {
      CHECK(e.cell == c);
      CHECK(e.lo.x() >= mesh.cell_min(c).x());
      CHECK(e.lo.y() >= mesh.cell_min(c).y());
      CHECK(e.hi.x() <= mesh.cell_max(c).x());
      CHECK(e.hi.y() <= mesh.cell_max(c).y());
      CHECK(e.hi.x() > e.lo.x());
      CHECK(e.hi.y() > e.lo.y());
      area += (e.hi.x() - e.lo.x()) * (e.hi.y() - e.lo.y());
    }
    CHECK(area == mesh.cell_size(c) * mesh.cell_size(c));
    for (const BezierElement& e : es) {
      // No knot line of a listed function crosses the element's interior.
      for (int a : e.functions) {
        for (double k : basis.function(a).knots_xi) CHECK_FALSE((k > e.lo.x() && k < e.hi.x()));
        for (double k : basis.function(a).knots_eta) CHECK_FALSE((k > e.lo.y() && k < e.hi.y()));
      }
      for (int k = 0; k < samples; ++k) {
        const Eigen::Vector2d st(u01(rng), u01(rng));
        const Eigen::Vector2d uv(e.lo.x() + st.x() * (e.hi.x() - e.lo.x()),
                                 e.lo.y() + st.y() * (e.hi.y() - e.lo.y()));
        CHECK((e.local(uv) - st).norm() < 1e-12);
        // Every function on the cell: the Bernstein form where listed, zero elsewhere.
        Eigen::Vector2d X = Eigen::Vector2d::Zero();
        double w = 0.0;
        std::size_t r = 0;
        for (int a : basis.functions_on_cell(c)) {
          const double direct = direct_value(basis.function(a), uv);
          if (r < e.functions.size() && e.functions[r] == a) {
            const double b = bernstein_value(e, static_cast<int>(r), st);
            max_err_n = std::max(max_err_n, std::abs(b - direct));
            X += b * map.control_points()[a];
            w += b;
            ++r;
          } else {
            CHECK(direct == 0.0);
          }
        }
        CHECK(r == e.functions.size());
        max_err_s = std::max(max_err_s, (X / w - map.derivatives(uv, 0, c).x).norm());
      }
    }
  }
  CHECK(max_err_n < 1e-13);
  CHECK(max_err_s < 1e-12);
  return split_cells;
}

TSplineMap smooth_map(TMesh mesh) {
  TSplineMap map = tspline::greville_identity_map(std::move(mesh));
  std::vector<Eigen::Vector2d> P = map.control_points();
  for (Eigen::Vector2d& p : P)
    p = Eigen::Vector2d(2.0 * p.x() + 0.3 * std::sin(3.0 * p.y()), p.y() + 0.2 * p.x() * p.x());
  map.set_control_points(P);
  return map;
}

// Max over the functions of |sum over cells of the quadrature of N_a - exact|,
// relative; the exact integral of a cubic B-spline on 5 knots is (k4 - k0) / 4.
// `quad(c, out)` gives the quadrature points of cell c.
template <class Quad>
double integral_error(const TSplineBasis& integrand, const TMesh& cells, Quad&& quad) {
  std::vector<double> sum(integrand.size(), 0.0);
  std::vector<tspline::QuadraturePoint> q;
  for (int c = 0; c < static_cast<int>(cells.num_cells()); ++c) {
    quad(c, q);
    for (const auto& p : q)
      for (std::size_t a = 0; a < integrand.size(); ++a) {
        const auto& f = integrand.function(static_cast<int>(a));
        if (p.uv.x() < f.knots_xi[0] || p.uv.x() > f.knots_xi[4] || p.uv.y() < f.knots_eta[0] ||
            p.uv.y() > f.knots_eta[4])
          continue;
        sum[a] += p.weight * direct_value(f, p.uv);
      }
  }
  double err = 0.0;
  for (std::size_t a = 0; a < integrand.size(); ++a) {
    const auto& f = integrand.function(static_cast<int>(a));
    const double exact = (f.knots_xi[4] - f.knots_xi[0]) * (f.knots_eta[4] - f.knots_eta[0]) / 16.0;
    err = std::max(err, std::abs(sum[a] - exact) / exact);
  }
  return err;
}

}  // namespace

TEST_SUITE("bezier_extraction") {
  TEST_CASE("univariate conversion: the Bernstein polynomials themselves and a B-spline piece") {
    // Open knots on [0,1]: the four cubic B-splines are the Bernstein polynomials.
    const std::array<std::array<double, 5>, 4> knots = {
        {{0, 0, 0, 0, 1}, {0, 0, 0, 1, 1}, {0, 0, 1, 1, 1}, {0, 1, 1, 1, 1}}};
    for (int i = 0; i < 4; ++i) {
      const std::array<double, 4> b = tspline::bspline_bernstein(knots[i], 0.0, 1.0);
      for (int k = 0; k < 4; ++k) CHECK(b[k] == doctest::Approx(i == k ? 1.0 : 0.0).epsilon(1e-14));
    }
    // The uniform cubic B-spline on its first span [0,1] is t^3/6: Bernstein (0, 0, 0, 1/6).
    const std::array<double, 4> b = tspline::bspline_bernstein({0, 1, 2, 3, 4}, 0.0, 1.0);
    CHECK(std::abs(b[0]) < 1e-15);
    CHECK(std::abs(b[1]) < 1e-15);
    CHECK(std::abs(b[2]) < 1e-15);
    CHECK(b[3] == doctest::Approx(1.0 / 6.0).epsilon(1e-14));
    // Outside the support: zero.
    for (double v : tspline::bspline_bernstein({0, 1, 2, 3, 4}, 4.0, 5.0)) CHECK(v == 0.0);
  }

  TEST_CASE("uniform mesh: one element per cell, partition of unity in Bernstein form") {
    TMesh m(2);
    m.build_topology();
    const TSplineMap map = smooth_map(m);
    CHECK(check_extraction(map, 5, 1) == 0);
    const tspline::BezierExtraction ex(map.basis());
    CHECK(ex.elements().size() == 16);
    for (const BezierElement& e : ex.elements()) {
      CHECK(e.functions.size() == 16);  // a bicubic patch: 4 x 4 B-splines
      for (int k = 0; k < 16; ++k) CHECK(e.C.col(k).sum() == doctest::Approx(1.0).epsilon(1e-14));
    }
  }

  TEST_CASE("T-meshes with hanging vertices: knot lines split cells; N_a and S reproduced at random points") {
    int split_total = 0;
    for (unsigned seed : {3u, 7u, 11u}) {
      CAPTURE(seed);
      const TSplineMap map = smooth_map(test_support::random_leaf_splits(2, 12, seed));
      REQUIRE(map.mesh().num_hanging_vertices() > 0);
      split_total += check_extraction(map, 4, seed);
      const tspline::BezierExtraction ex(map.basis());
      CHECK(ex.cell_begin(0) == 0);
      CHECK(ex.cell_begin(static_cast<int>(map.mesh().num_cells())) == ex.elements().size());
      for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c) {
        CHECK(ex.cell_begin(c + 1) > ex.cell_begin(c));
        for (std::size_t k = ex.cell_begin(c); k < ex.cell_begin(c + 1); ++k)
          CHECK(ex.elements()[k].cell == c);
      }
    }
    // With T-junctions some functions' knot lines cross cell interiors.
    CHECK(split_total > 0);
  }

  TEST_CASE("the map per cell from its Bezier elements (element_map.h): S and J as TSplineMap::derivatives, "
            "cell boundaries and knot lines inside cells included, far from the origin") {
    // A map in km far from (0, 0) (as real coastlines in a projected CRS):
    // the evaluator works relative to a control point of each element.
    for (unsigned seed : {3u, 7u}) {
      CAPTURE(seed);
      TSplineMap map = smooth_map(test_support::random_leaf_splits(2, 12, seed));
      std::vector<Eigen::Vector2d> P = map.control_points();
      const Eigen::Vector2d far(4.0e5, -2.5e6);
      for (Eigen::Vector2d& p : P) p = far + 37.0 * p;
      map.set_control_points(P);
      const tspline::BezierExtraction ex(map.basis());
      tspline::CellMapEvaluator at_cell(ex, map.control_points());
      int split_cells = 0, boundary_points = 0;
      double err_x = 0.0, err_j = 0.0, scale_j = 0.0;
      for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c) {
        if (ex.cell_begin(c + 1) - ex.cell_begin(c) > 1) ++split_cells;
        at_cell.set_cell(c);
        CHECK(at_cell.cell() == c);
        const Eigen::Vector2d lo = map.mesh().cell_min(c), hi = map.mesh().cell_max(c);
        // A 9 x 9 grid: the cell's sides, its corners and its midlines (where
        // knot lines split cells into elements) are all sampled.
        for (int j = 0; j <= 8; ++j)
          for (int i = 0; i <= 8; ++i) {
            const Eigen::Vector2d uv(lo.x() + (hi.x() - lo.x()) * i / 8, lo.y() + (hi.y() - lo.y()) * j / 8);
            if (i == 0 || i == 8 || j == 0 || j == 8) ++boundary_points;
            const tspline::MapDerivatives a = at_cell.at(uv), b = map.derivatives(uv, 1, c);
            err_x = std::max(err_x, (a.x - b.x).norm());
            err_j = std::max(err_j, (a.J - b.J).norm());
            scale_j = std::max(scale_j, b.J.norm());
          }
      }
      CHECK(split_cells > 0);
      CHECK(boundary_points > 0);
      // |P| ~ 2.5e6: S agrees to a few ulps of the coordinates; J (~37 x 2)
      // to the basis path's cancellation, about eps |P| / cell size.
      CHECK(err_x < 1e-8);
      CHECK(err_j < 1e-6 * scale_j);
      // ElementMap alone: at local (s, t) of an element, the same as at its
      // parametric point.
      const tspline::BezierElement& e = ex.elements()[ex.elements().size() / 2];
      const tspline::ElementMap em(e, map.control_points());
      const Eigen::Vector2d uv = e.lo + Eigen::Vector2d(0.25, 0.75).cwiseProduct(e.hi - e.lo);
      CHECK((em.at_local(0.25, 0.75).x - map.derivatives(uv, 1, e.cell).x).norm() < 1e-8);
      CHECK((em.at(uv).J - map.derivatives(uv, 1, e.cell).J).norm() < 1e-6 * scale_j);
    }
  }

  TEST_CASE("quadrature per Bezier element integrates every blending function exactly (not so per cell)") {
    const TMesh mesh = test_support::random_leaf_splits(2, 12, 7);
    const TSplineBasis basis(mesh);
    REQUIRE(mesh.num_hanging_vertices() > 0);
    // 2 x 2 Gauss points are exact for bicubics: exact on every element.
    const double per_element = integral_error(
        basis, mesh,
        [&](int c, std::vector<tspline::QuadraturePoint>& q) { tspline::cell_quadrature(basis, c, 2, q); });
    CHECK(per_element < 1e-13);
    // The same rule on whole cells is not exact where knot lines cross cells.
    const double per_cell = integral_error(basis, mesh, [&](int c, std::vector<tspline::QuadraturePoint>& q) {
      std::vector<double> gp, gw;
      tspline::detail::gauss_points_01(2, gp, gw);
      const Eigen::Vector2d lo = mesh.cell_min(c), len = mesh.cell_max(c) - lo;
      q.clear();
      for (std::size_t a = 0; a < gp.size(); ++a)
        for (std::size_t b = 0; b < gp.size(); ++b)
          q.push_back(
              {{lo.x() + gp[a] * len.x(), lo.y() + gp[b] * len.y()}, gw[a] * gw[b] * len.x() * len.y()});
    });
    CHECK(per_cell > 1e-6);
    // Weights of each cell add up to its area.
    std::vector<tspline::QuadraturePoint> q;
    for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
      tspline::cell_quadrature(basis, c, 3, q);
      double w = 0.0;
      for (const auto& p : q) w += p.weight;
      CHECK(w == doctest::Approx(mesh.cell_size(c) * mesh.cell_size(c)).epsilon(1e-14));
    }
  }

  TEST_CASE(
      "quadrature on a finer analysis mesh, split by the geometry's knot lines too, integrates the geometry "
      "functions exactly") {
    const TMesh geometry_mesh = test_support::random_leaf_splits(2, 8, 11);
    const TSplineBasis geometry(geometry_mesh);
    // The analysis mesh: the geometry mesh with some cells split once more.
    TMesh analysis_mesh = geometry_mesh;
    for (int c = 0; c < static_cast<int>(geometry_mesh.num_cells()); c += 3)
      analysis_mesh.refine(geometry_mesh.cell_node(c));
    analysis_mesh.balance();
    analysis_mesh.build_topology();
    const TSplineBasis analysis(analysis_mesh);
    auto geometry_cell = [&](int c) {
      return geometry.locate(0.5 * (analysis_mesh.cell_min(c) + analysis_mesh.cell_max(c)));
    };
    const double with_geometry = integral_error(geometry, analysis_mesh, [&](int c, auto& q) {
      tspline::cell_quadrature(analysis, c, 2, q, &geometry, geometry_cell(c));
    });
    CHECK(with_geometry < 1e-13);
    // And the analysis functions, too.
    CHECK(integral_error(analysis, analysis_mesh, [&](int c, auto& q) {
            tspline::cell_quadrature(analysis, c, 2, q, &geometry, geometry_cell(c));
          }) < 1e-13);
  }
}
