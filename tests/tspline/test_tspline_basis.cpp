// Cubic T-spline basis: B-splines, knot vectors by ray casting, open knot
// structure at the border, support lists, rational normalization (Eq. 6).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <set>

#include "test_support.h"
#include "tspline/errors.h"
#include "tspline/spline/map_side.h"
#include "tspline/spline/tspline_basis.h"
#include "tspline/spline/tspline_map.h"
#include "tspline/tmesh/tmesh.h"

using tspline::BasisValues;
using tspline::BlendingFunction;
using tspline::TMesh;
using tspline::TSplineBasis;
using Kind = BlendingFunction::Kind;

namespace {

// Independent reference: k-th derivative of N_{i,p} over the full knot vector
// U, by the textbook recursions (Cox-de Boor for values, the p-fold derivative
// formula for derivatives), 0/0 := 0. At t == U.back() the last non-empty span
// is used (left limit), matching the library's convention at the border 1.
double ref_bspline(const std::vector<double>& U, int i, int p, double t, int k = 0) {
  if (k > 0) {
    if (p == 0) return 0.0;
    const double a = U[i + p] - U[i], b = U[i + p + 1] - U[i + 1];
    double r = 0.0;
    if (a != 0.0) r += ref_bspline(U, i, p - 1, t, k - 1) / a;
    if (b != 0.0) r -= ref_bspline(U, i + 1, p - 1, t, k - 1) / b;
    return p * r;
  }
  if (p == 0) {
    if (U[i] <= t && t < U[i + 1]) return 1.0;
    if (t == U.back() && U.back() == 1.0 && U[i] < U[i + 1] && U[i + 1] == t) {
      // left limit at 1: the last non-empty span of U
      for (std::size_t j = i + 1; j + 1 < U.size(); ++j)
        if (U[j] < U[j + 1]) return 0.0;
      return 1.0;
    }
    return 0.0;
  }
  double r = 0.0;
  const double a = U[i + p] - U[i], b = U[i + p + 1] - U[i + 1];
  if (a != 0.0) r += (t - U[i]) / a * ref_bspline(U, i, p - 1, t);
  if (b != 0.0) r += (U[i + p + 1] - t) / b * ref_bspline(U, i + 1, p - 1, t);
  return r;
}

std::vector<double> open_knots(int n) {
  std::vector<double> U{0, 0, 0};
  for (int i = 0; i <= n; ++i) U.push_back(static_cast<double>(i) / n);
  U.insert(U.end(), {1, 1, 1});
  return U;
}

using test_support::random_tmesh;

// Cells touching the border refined `depth` more times (as boundary refinement does).
TMesh boundary_mesh(int depth) {
  TMesh m(2);
  for (int d = 0; d < depth; ++d) {
    const std::size_t count = m.nodes().size();
    for (std::size_t n = 0; n < count; ++n) {
      const tspline::QuadNode q = m.node(static_cast<int>(n));
      if (!q.is_leaf()) continue;
      const tspline::IPoint lo = TMesh::node_min(q), hi = TMesh::node_max(q);
      if (lo.x == 0 || lo.y == 0 || hi.x == TMesh::kRoot || hi.y == TMesh::kRoot) m.refine(static_cast<int>(n));
    }
  }
  m.balance();
  m.build_topology();
  return m;
}

std::array<double, 5> K(double a, double b, double c, double d, double e) { return {a, b, c, d, e}; }

// A point of cell c at relative position (s, t) in [0,1]^2.
Eigen::Vector2d in_cell(const TMesh& m, int c, double s, double t) {
  const Eigen::Vector2d lo = m.cell_min(c), hi = m.cell_max(c);
  return {lo.x() + s * (hi.x() - lo.x()), lo.y() + t * (hi.y() - lo.y())};
}

// Random points of cells: in_cell at relative positions uniform in [lo, hi)^2.
struct RandomCellPoints {
  RandomCellPoints(unsigned seed, double lo, double hi) : rng(seed), u(lo, hi) {}
  Eigen::Vector2d operator()(const TMesh& m, int c) { return in_cell(m, c, u(rng), u(rng)); }
  std::mt19937 rng;
  std::uniform_real_distribution<double> u;
};

// random_tmesh(seed, rounds, max_level), required to have hanging vertices.
TMesh random_tmesh_with_hanging_vertices(unsigned seed, int rounds, int max_level) {
  TMesh m = random_tmesh(seed, rounds, max_level);
  REQUIRE(m.num_hanging_vertices() > 0);
  return m;
}

// Sum of R and of its derivatives at uv in cell c: 1, 0, 0 (relative to the scale).
void check_partition_of_unity(const TSplineBasis& B, int c, const Eigen::Vector2d& uv) {
  BasisValues v;
  B.evaluate(c, uv, v);
  double s = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, scale1 = 0, scale2 = 0;
  for (std::size_t k = 0; k < v.ids.size(); ++k) {
    s += v.R[k];
    sx += v.R_xi[k];
    sy += v.R_eta[k];
    sxx += v.R_xixi[k];
    sxy += v.R_xieta[k];
    syy += v.R_etaeta[k];
    scale1 = std::max({scale1, std::abs(v.R_xi[k]), std::abs(v.R_eta[k])});
    scale2 = std::max({scale2, std::abs(v.R_xixi[k]), std::abs(v.R_xieta[k]), std::abs(v.R_etaeta[k])});
  }
  CHECK(std::abs(s - 1.0) < 1e-14);
  CHECK(std::abs(sx) <= 1e-13 * scale1);
  CHECK(std::abs(sy) <= 1e-13 * scale1);
  CHECK(std::abs(sxx) <= 1e-13 * scale2);
  CHECK(std::abs(sxy) <= 1e-13 * scale2);
  CHECK(std::abs(syy) <= 1e-13 * scale2);
}

void check_partition_everywhere(const TMesh& m, unsigned seed) {
  const TSplineBasis B(m);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) {
    for (int k = 0; k < 3; ++k) check_partition_of_unity(B, c, in_cell(m, c, u(rng), u(rng)));
    // corners, edge midpoints (cell lines, border of the square)
    for (double s : {0.0, 0.5, 1.0})
      for (double t : {0.0, 0.5, 1.0}) check_partition_of_unity(B, c, in_cell(m, c, s, t));
  }
  for (int k = 0; k < 200; ++k) {  // the border of the square through locate()
    const double t = u(rng);
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(t, 0), Eigen::Vector2d(t, 1), Eigen::Vector2d(0, t),
                                     Eigen::Vector2d(1, t)})
      check_partition_of_unity(B, B.locate(p), p);
  }
}

struct KindCounts {
  std::size_t anchor = 0, edge = 0, corner = 0;
};
KindCounts count_kinds(const TSplineBasis& B) {
  KindCounts k;
  for (const BlendingFunction& f : B.functions()) {
    if (f.kind == Kind::Anchor) ++k.anchor;
    if (f.kind == Kind::EdgeExtra) ++k.edge;
    if (f.kind == Kind::CornerExtra) ++k.corner;
  }
  return k;
}

}  // namespace

TEST_SUITE("tspline_basis") {
  TEST_CASE(
      "cubic_bspline_vanishes only where cubic_bspline is +0; values-only evaluation is the full one's") {
    // Knot vectors with simple, double, triple and quadruple end knots, at the
    // border and inside, at every knot and at random points around them.
    const std::vector<std::array<double, 5>> vectors = {
        K(0, 0.25, 0.5, 0.75, 1),     K(0, 0, 0, 0, 0.5),         K(0, 0, 0, 0.3, 0.7),
        K(0, 0, 0.2, 0.6, 0.65),      K(0.2, 0.2, 0.2, 0.2, 0.8), K(0.2, 0.2, 0.2, 0.5, 0.8),
        K(0.5, 1, 1, 1, 1),           K(0.25, 0.5, 1, 1, 1),      K(0.3, 0.6, 0.6, 0.6, 0.6),
        K(0.3, 0.3, 0.55, 0.55, 0.9), K(0.4, 0.4, 0.4, 0.4, 0.4)};
    std::mt19937 rng(5);
    std::size_t said = 0;
    for (const auto& k : vectors) {
      std::vector<double> ts(k.begin(), k.end());
      std::uniform_real_distribution<double> u(k[0] - 0.1, k[4] + 0.1);
      for (int i = 0; i < 50; ++i) ts.push_back(u(rng));
      ts.push_back(0.0), ts.push_back(1.0);
      for (double t : ts) {
        if (!tspline::cubic_bspline_vanishes(k, t)) continue;
        ++said;
        const double v = tspline::cubic_bspline(k, t);
        CAPTURE(t);
        CHECK(v == 0.0);
        CHECK_FALSE(std::signbit(v));
      }
    }
    CHECK(said > 100);
    // The same function right of a simple knot, and a clamped start: not zero.
    CHECK_FALSE(tspline::cubic_bspline_vanishes(K(0, 0, 0, 0, 0.5), 0.0));
    CHECK_FALSE(tspline::cubic_bspline_vanishes(K(0.5, 1, 1, 1, 1), 1.0));
    // TSplineBasis::evaluate with values only skips such factors: the values
    // must be those of the evaluation with derivatives, bit for bit, at cell
    // corners, on edges and inside, on a graded T-mesh.
    const TMesh m = boundary_mesh(3);
    const TSplineBasis B(m);
    tspline::BasisValues full, values;
    std::size_t points = 0, zeros = 0;
    for (int c = 0; c < static_cast<int>(m.num_cells()); ++c)
      for (const double s : {0.0, 0.25, 0.5, 1.0})
        for (const double t : {0.0, 0.3, 1.0}) {
          const Eigen::Vector2d uv = in_cell(m, c, s, t);
          B.evaluate(c, uv, full, 1);
          B.evaluate(c, uv, values, 0);
          REQUIRE(values.ids == full.ids);
          for (std::size_t a = 0; a < full.R.size(); ++a) {
            CHECK(values.R[a] == full.R[a]);
            CHECK(std::signbit(values.R[a]) == std::signbit(full.R[a]));
            zeros += full.R[a] == 0.0;
          }
          ++points;
        }
    CHECK(points > 100);
    CHECK(zeros > points);  // (most functions of a cell vanish on its edges)
  }

  TEST_CASE("MapSide gives TSplineMap::point's doubles along each side of the square") {
    // A T-mesh graded towards the border, with random control points (a
    // rational map where the functions do not sum to 1): at every knot of a
    // side, on a fine grid and at random parameters, bit for bit.
    TMesh m = boundary_mesh(3);
    const tspline::TSplineMap shape(m);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2), t01(0.0, 1.0);
    std::vector<Eigen::Vector2d> P;
    for (const BlendingFunction& f : shape.basis().functions())
      P.emplace_back(1e3 + f.interpolation_point.x() + 0.1 * jitter(rng),
                     -2e3 + f.interpolation_point.y() + 0.1 * jitter(rng));
    const tspline::TSplineMap map(m, P);
    std::size_t points = 0;
    for (int side = 0; side < 4; ++side) {
      const tspline::MapSide along(map, side);
      std::vector<double> ts;
      for (int k = 0; k <= 256; ++k) ts.push_back(k / 256.0);
      for (int k = 0; k < 200; ++k) ts.push_back(t01(rng));
      for (const double t : ts) {
        const Eigen::Vector2d uv = side == 0   ? Eigen::Vector2d(t, 0.0)
                                   : side == 1 ? Eigen::Vector2d(1.0, t)
                                   : side == 2 ? Eigen::Vector2d(1.0 - t, 1.0)
                                               : Eigen::Vector2d(0.0, 1.0 - t);
        const Eigen::Vector2d a = along.at(t), b = map.point(uv);
        CAPTURE(side);
        CAPTURE(t);
        CHECK(a.x() == b.x());
        CHECK(a.y() == b.y());
        ++points;
      }
    }
    CHECK(points == 4 * 457);
    CHECK_THROWS_AS(tspline::MapSide(map, 4), tspline::InputError);
  }

  TEST_CASE("a copied map's basis is the basis of its own T-mesh, the same as one made from it") {
    TMesh m = boundary_mesh(3);
    const tspline::TSplineMap shape(m);
    std::vector<Eigen::Vector2d> P;
    for (const BlendingFunction& f : shape.basis().functions())
      P.emplace_back(f.interpolation_point.x() + 0.05 * f.interpolation_point.y(), f.interpolation_point.y());
    std::optional<tspline::TSplineMap> original(std::in_place, m, P);
    const tspline::TSplineMap copy(*original);
    const tspline::TSplineBasis made(copy.mesh());  // made afresh from the copy's T-mesh
    CHECK(&copy.basis().mesh() == &copy.mesh());
    REQUIRE(copy.basis().size() == made.size());
    for (int a = 0; a < static_cast<int>(made.size()); ++a) {
      CHECK(copy.basis().function(a).knots_xi == made.function(a).knots_xi);
      CHECK(copy.basis().function(a).knots_eta == made.function(a).knots_eta);
      CHECK(copy.basis().function(a).vertex == made.function(a).vertex);
    }
    for (int c = 0; c < static_cast<int>(copy.mesh().num_cells()); ++c)
      CHECK(copy.basis().functions_on_cell(c) == made.functions_on_cell(c));
    // The original gone, the copy evaluates as it did (nothing points into the original).
    const Eigen::Vector2d uv(0.3, 0.7);
    const Eigen::Vector2d before = original->point(uv);
    original.reset();
    CHECK(copy.point(uv) == before);
  }

  TEST_CASE("cubic_bspline matches Cox-de Boor, values and derivatives") {
    const std::vector<std::array<double, 5>> vectors = {
        K(0, 0.25, 0.5, 0.75, 1),      K(0.1, 0.3, 0.35, 0.7, 0.9),  K(0, 0, 0, 0, 0.5),
        K(0, 0, 0, 0.3, 0.7),          K(0, 0, 0.2, 0.6, 0.65),       K(0.1, 0.4, 0.4, 0.6, 0.9),
        K(0.2, 0.5, 0.5, 0.5, 0.8),    K(0.2, 0.2, 0.2, 0.2, 0.8),    K(0.3, 0.6, 0.6, 0.6, 0.6),
        K(0.5, 1, 1, 1, 1),            K(0, 0.25, 1, 1, 1),           K(0.125, 0.5, 0.75, 1, 1),
        K(0.3, 0.3, 0.55, 0.55, 0.9)};
    std::mt19937 rng(3);
    for (const auto& k : vectors) {
      CAPTURE(k[0]);
      CAPTURE(k[1]);
      CAPTURE(k[2]);
      CAPTURE(k[3]);
      CAPTURE(k[4]);
      const std::vector<double> U(k.begin(), k.end());
      std::vector<double> ts(k.begin(), k.end());
      std::uniform_real_distribution<double> u(k[0] - 0.1, k[4] + 0.1);
      for (int i = 0; i < 200; ++i) ts.push_back(u(rng));
      ts.push_back(1.0);
      ts.push_back(0.0);
      for (double t : ts) {
        double d1 = 0, d2 = 0;
        const double v = tspline::cubic_bspline(k, t, &d1, &d2);
        CAPTURE(t);
        CHECK(std::abs(v - ref_bspline(U, 0, 3, t)) < 1e-14);
        const double scale = 1.0 / std::pow(k[4] - k[0], 2);
        CHECK(std::abs(d1 - ref_bspline(U, 0, 3, t, 1)) < 1e-12 * scale);
        CHECK(std::abs(d2 - ref_bspline(U, 0, 3, t, 2)) < 1e-11 * scale * scale);
        // finite differences away from the knots (the pieces are polynomials)
        const double h = 1e-5;
        bool near_knot = false;
        for (double kk : k) near_knot = near_knot || std::abs(t - kk) < 2 * h;
        if (near_knot) continue;
        double d1p = 0, d1m = 0;
        const double vp = tspline::cubic_bspline(k, t + h, &d1p);
        const double vm = tspline::cubic_bspline(k, t - h, &d1m);
        CHECK(std::abs((vp - vm) / (2 * h) - d1) < 1e-6 * (1 + std::abs(d1)) * scale);
        CHECK(std::abs((d1p - d1m) / (2 * h) - d2) < 1e-6 * (1 + std::abs(d2)) * scale);
      }
    }
    // null derivative pointers are allowed; all of the support of a simple cubic is positive
    CHECK(tspline::cubic_bspline(K(0, 1, 2, 3, 4), 2.0) == doctest::Approx(2.0 / 3.0));
    CHECK(tspline::cubic_bspline(K(0, 0, 0, 0, 0.5), 0.0) == 1.0);
    CHECK(tspline::cubic_bspline(K(0.5, 1, 1, 1, 1), 1.0) == 1.0);  // left limit at the border
  }

  TEST_CASE("uniform meshes give the tensor product open-knot B-splines") {
    for (int level = 0; level <= 3; ++level) {
      CAPTURE(level);
      TMesh m(level);
      m.build_topology();
      const TSplineBasis B(m);
      const int n = 1 << level;
      REQUIRE(B.size() == static_cast<std::size_t>((n + 3) * (n + 3)));
      const std::vector<double> U = open_knots(n);
      // Each function's knots are a window U[i..i+4] x U[j..j+4]; each (i, j) exactly once.
      std::vector<std::pair<int, int>> index(B.size(), {-1, -1});
      std::set<std::pair<int, int>> seen;
      for (std::size_t a = 0; a < B.size(); ++a) {
        const BlendingFunction& f = B.function(static_cast<int>(a));
        for (int i = 0; i < n + 3; ++i) {
          if (std::equal(f.knots_xi.begin(), f.knots_xi.end(), U.begin() + i)) index[a].first = i;
          if (std::equal(f.knots_eta.begin(), f.knots_eta.end(), U.begin() + i)) index[a].second = i;
        }
        REQUIRE(index[a].first >= 0);
        REQUIRE(index[a].second >= 0);
        seen.insert(index[a]);
      }
      CHECK(seen.size() == B.size());
      // R (= N: S is 1 on a tensor mesh) against the reference at random points.
      std::mt19937 rng(level + 11);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      BasisValues v;
      for (int k = 0; k < 300; ++k) {
        Eigen::Vector2d p(u(rng), u(rng));
        if (k < 4) p = Eigen::Vector2d(k & 1, k >> 1);  // the corners of the square
        B.evaluate(p, v);
        std::vector<double> R(B.size(), 0.0);
        for (std::size_t q = 0; q < v.ids.size(); ++q) R[v.ids[q]] = v.R[q];
        for (std::size_t a = 0; a < B.size(); ++a) {
          const double expected =
              ref_bspline(U, index[a].first, 3, p.x()) * ref_bspline(U, index[a].second, 3, p.y());
          CHECK(std::abs(R[a] - expected) < 1e-14);
        }
      }
    }
  }

  TEST_CASE("partition of unity on uniform and adaptive T-meshes") {
    for (int level = 0; level <= 3; ++level) {
      TMesh m(level);
      m.build_topology();
      check_partition_everywhere(m, 100 + level);
    }
    const TMesh r = random_tmesh_with_hanging_vertices(7, 120, 8);
    check_partition_everywhere(r, 5);
    const TMesh b = boundary_mesh(4);
    REQUIRE(b.num_hanging_vertices() > 0);
    check_partition_everywhere(b, 6);
  }

  TEST_CASE("derivatives of R match finite differences on a T-mesh") {
    const TMesh m = random_tmesh_with_hanging_vertices(21, 60, 7);
    const TSplineBasis B(m);
    RandomCellPoints random_point(4, 0.1, 0.9);
    BasisValues v, vxp, vxm, vyp, vym;
    for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) {
      const double h = 1e-5 * m.cell_size(c);
      const Eigen::Vector2d p = random_point(m, c);
      B.evaluate(c, p, v);
      B.evaluate(c, p + Eigen::Vector2d(h, 0), vxp);
      B.evaluate(c, p - Eigen::Vector2d(h, 0), vxm);
      B.evaluate(c, p + Eigen::Vector2d(0, h), vyp);
      B.evaluate(c, p - Eigen::Vector2d(0, h), vym);
      double s1 = 0, s2 = 0;
      for (std::size_t k = 0; k < v.ids.size(); ++k) {
        s1 = std::max({s1, std::abs(v.R_xi[k]), std::abs(v.R_eta[k])});
        s2 = std::max({s2, std::abs(v.R_xixi[k]), std::abs(v.R_xieta[k]), std::abs(v.R_etaeta[k])});
      }
      for (std::size_t k = 0; k < v.ids.size(); ++k) {
        const auto close = [](double fd, double exact, double scale) {
          return std::abs(fd - exact) <= 1e-6 * std::max(std::abs(exact), scale);
        };
        CHECK(close((vxp.R[k] - vxm.R[k]) / (2 * h), v.R_xi[k], 1e-3 * s1));
        CHECK(close((vyp.R[k] - vym.R[k]) / (2 * h), v.R_eta[k], 1e-3 * s1));
        CHECK(close((vxp.R_xi[k] - vxm.R_xi[k]) / (2 * h), v.R_xixi[k], 1e-3 * s2));
        CHECK(close((vyp.R_xi[k] - vym.R_xi[k]) / (2 * h), v.R_xieta[k], 1e-3 * s2));
        CHECK(close((vxp.R_eta[k] - vxm.R_eta[k]) / (2 * h), v.R_xieta[k], 1e-3 * s2));
        CHECK(close((vyp.R_eta[k] - vym.R_eta[k]) / (2 * h), v.R_etaeta[k], 1e-3 * s2));
      }
    }
  }

  TEST_CASE("knot vectors by ray casting on a hand-built T-mesh") {
    // 2x2 mesh with the lower-left cell split. Coordinates in quarters:
    //
    //  1   +-------+-------+
    //      |       |       |
    //      |       |       |
    // 1/2  +---T---+-------+    T = (1/4,1/2): T-junction in the top-left cell
    //      |   |   |       |
    // 1/4  +---+---T       |    T = (1/2,1/4): T-junction in the lower-right cell
    //      |   |   |       |
    //  0   +---+---+-------+
    //      0  1/4 1/2      1
    TMesh m(1);
    m.refine(m.leaf_at_doubled(1, 1));
    m.build_topology();
    const TSplineBasis B(m);
    const std::int64_t q = TMesh::kRoot / 4;
    auto functions_at = [&](std::int64_t x, std::int64_t y) {
      const int v = m.find_vertex({x * q, y * q});
      REQUIRE(v >= 0);
      std::vector<BlendingFunction> out;
      for (const BlendingFunction& f : B.functions())
        if (f.vertex == v) out.push_back(f);
      return out;
    };
    auto check = [](const BlendingFunction& f, std::array<double, 5> kx, std::array<double, 5> ky) {
      CHECK(f.knots_xi == kx);
      CHECK(f.knots_eta == ky);
    };
    {  // regular inner vertex: xi rays cross 1/2 then 1 to the right, 0 then the border to the left
      const auto fs = functions_at(1, 1);
      REQUIRE(fs.size() == 1);
      check(fs[0], K(0, 0, 0.25, 0.5, 1), K(0, 0, 0.25, 0.5, 1));
      CHECK(fs[0].interpolation_point == Eigen::Vector2d(0.25, 0.25));
    }
    {  // T-junction (1/2,1/4): right ray in the big cell hits 1; up: 1/2 then 1
      const auto fs = functions_at(2, 1);
      REQUIRE(fs.size() == 1);
      check(fs[0], K(0, 0.25, 0.5, 1, 1), K(0, 0, 0.25, 0.5, 1));
    }
    {  // T-junction (1/4,1/2): upward ray inside the top-left cell reaches 1 directly
      const auto fs = functions_at(1, 2);
      REQUIRE(fs.size() == 1);
      check(fs[0], K(0, 0, 0.25, 0.5, 1), K(0, 0.25, 0.5, 1, 1));
    }
    {  // centre: leftward ray along eta = 1/2 stops at 1/4 (edge below the ray)
      const auto fs = functions_at(2, 2);
      REQUIRE(fs.size() == 1);
      check(fs[0], K(0, 0.25, 0.5, 1, 1), K(0, 0.25, 0.5, 1, 1));
    }
    {  // border vertex (1/4,0): anchor with 4 repeated knots, extra with 3
      const auto fs = functions_at(1, 0);
      REQUIRE(fs.size() == 2);
      CHECK(fs[0].kind == Kind::Anchor);
      check(fs[0], K(0, 0, 0.25, 0.5, 1), K(0, 0, 0, 0, 0.25));
      CHECK(fs[1].kind == Kind::EdgeExtra);
      check(fs[1], K(0, 0, 0.25, 0.5, 1), K(0, 0, 0, 0.25, 0.5));
      CHECK(fs[1].interpolation_point == Eigen::Vector2d(0.25, 0.125));
    }
    {  // corner (1,0): leftward border ray crosses 1/2 then 1/4; upward 1/2 then 1
      const auto fs = functions_at(4, 0);
      REQUIRE(fs.size() == 4);
      CHECK(fs[0].kind == Kind::Anchor);
      check(fs[0], K(0.5, 1, 1, 1, 1), K(0, 0, 0, 0, 0.5));
      CHECK(fs[0].interpolation_point == Eigen::Vector2d(1, 0));
      CHECK(fs[1].kind == Kind::EdgeExtra);
      check(fs[1], K(0.25, 0.5, 1, 1, 1), K(0, 0, 0, 0, 0.5));
      CHECK(fs[1].interpolation_point == Eigen::Vector2d(0.75, 0));
      CHECK(fs[2].kind == Kind::EdgeExtra);
      check(fs[2], K(0.5, 1, 1, 1, 1), K(0, 0, 0, 0.5, 1));
      CHECK(fs[2].interpolation_point == Eigen::Vector2d(1, 0.25));
      CHECK(fs[3].kind == Kind::CornerExtra);
      check(fs[3], K(0.25, 0.5, 1, 1, 1), K(0, 0, 0, 0.5, 1));
      CHECK(fs[3].interpolation_point == Eigen::Vector2d(0.75, 0.25));  // centre of the corner cell
    }
    {  // corner (0,0): first spans are 1/4 in both directions
      const auto fs = functions_at(0, 0);
      REQUIRE(fs.size() == 4);
      check(fs[0], K(0, 0, 0, 0, 0.25), K(0, 0, 0, 0, 0.25));
      check(fs[3], K(0, 0, 0, 0.25, 0.5), K(0, 0, 0, 0.25, 0.5));
      CHECK(fs[3].interpolation_point == Eigen::Vector2d(0.125, 0.125));
    }
    CHECK(B.size() == m.num_vertices() + (10 - 4) + 12);  // 10 border vertices, 4 of them corners
  }

  TEST_CASE("support lists contain every function non-zero on the cell") {
    const TMesh m = random_tmesh_with_hanging_vertices(9, 40, 6);
    const TSplineBasis B(m);
    RandomCellPoints random_point(8, 0.0, 1.0);
    for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) {
      const std::vector<int>& ids = B.functions_on_cell(c);
      CHECK(std::is_sorted(ids.begin(), ids.end()));
      CHECK(std::adjacent_find(ids.begin(), ids.end()) == ids.end());
      const Eigen::Vector2d lo = m.cell_min(c), hi = m.cell_max(c);
      for (int id : ids) {
        const BlendingFunction& f = B.function(id);
        CHECK(f.knots_xi[0] < hi.x());
        CHECK(f.knots_xi[4] > lo.x());
        CHECK(f.knots_eta[0] < hi.y());
        CHECK(f.knots_eta[4] > lo.y());
      }
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d p = random_point(m, c);
        for (int a = 0; a < static_cast<int>(B.size()); ++a) {
          const BlendingFunction& f = B.function(a);
          const double N = tspline::cubic_bspline(f.knots_xi, p.x()) * tspline::cubic_bspline(f.knots_eta, p.y());
          if (N != 0.0) CHECK(std::binary_search(ids.begin(), ids.end(), a));
        }
      }
    }
  }

  TEST_CASE("function counts: one extra per border vertex, three per corner") {
    std::vector<TMesh> meshes;
    for (int level = 0; level <= 3; ++level) {
      meshes.emplace_back(level);
      meshes.back().build_topology();
    }
    meshes.push_back(random_tmesh(7, 120, 8));
    meshes.push_back(boundary_mesh(3));
    for (const TMesh& m : meshes) {
      const TSplineBasis B(m);
      std::size_t border = 0;
      for (int v = 0; v < static_cast<int>(m.num_vertices()); ++v) border += m.vertex_on_boundary(v) ? 1 : 0;
      const KindCounts k = count_kinds(B);
      CHECK(k.anchor == m.num_vertices());
      // non-corner border vertices: 1 EdgeExtra; corners: 2 EdgeExtra + 1 CornerExtra
      CHECK(k.edge == border - 4 + 8);
      CHECK(k.corner == 4);
      CHECK(B.size() == m.num_vertices() + border + 8);
      std::map<int, int> per_vertex;
      for (const BlendingFunction& f : B.functions()) ++per_vertex[f.vertex];
      for (const auto& [v, count] : per_vertex) {
        const tspline::IPoint p = m.vertex_ipos(v);
        const bool bx = p.x == 0 || p.x == TMesh::kRoot, by = p.y == 0 || p.y == TMesh::kRoot;
        CHECK(count == (bx && by ? 4 : (bx || by ? 2 : 1)));
      }
    }
  }

  TEST_CASE("locate and evaluate conventions") {
    const TMesh m = random_tmesh(3, 30, 6);
    const TSplineBasis B(m);
    for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) {
      CHECK(B.locate(in_cell(m, c, 0.5, 0.5)) == c);
      CHECK(B.locate(m.cell_min(c)) == c);  // lower-left corner belongs to the cell
    }
    CHECK(B.locate({1.0, 1.0}) >= 0);
    CHECK_THROWS_AS(B.locate({1.5, 0.5}), tspline::InputError);
    BasisValues v;
    B.evaluate({0.3, 0.7}, v, 0);
    CHECK(v.R_xi.empty());
    CHECK(v.R.size() == v.ids.size());
    B.evaluate({0.3, 0.7}, v, 1);
    CHECK(v.R_xi.size() == v.ids.size());
    CHECK(v.R_xixi.empty());
  }
}
