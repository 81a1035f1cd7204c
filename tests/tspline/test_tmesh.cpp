// T-mesh invariants, boundary refinement, Coons start.
#include <doctest/doctest.h>

#include <random>

#include "test_support.h"

#include "tspline/errors.h"
#include "tspline/boundary/boundary_refinement.h"
#include "tspline/tmesh/coons.h"
#include "tspline/boundary/corners.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/tmesh/tmesh.h"

using tspline::IPoint;
using tspline::TMesh;

namespace {

tspline::BoundaryMap load_boundary(const std::string& name) {
  tspline::Polygon p = tspline::validate_polygon(tspline::io::read_polygon(test_support::polygon_file(name)));
  tspline::Corners c = tspline::choose_corners(p);
  return tspline::BoundaryMap(std::move(p), std::move(c));
}

}  // namespace

TEST_SUITE("tmesh") {
  TEST_CASE("uniform mesh counts") {
    for (int level = 0; level <= 4; ++level) {
      TMesh m(level);
      m.build_topology();
      const std::size_t n = std::size_t{1} << level;
      CHECK(m.num_cells() == n * n);
      CHECK(m.num_vertices() == (n + 1) * (n + 1));
      CHECK(m.num_hanging_vertices() == 0);
      CHECK(m.check_invariants() == "");
    }
  }

  TEST_CASE("one split creates four hanging vertices' worth of topology") {
    TMesh m(1);
    m.refine(m.leaf_at_doubled(1, 1));  // the lower-left cell
    m.build_topology();
    CHECK(m.num_cells() == 7);
    CHECK(m.num_vertices() == 9 + 5);
    // (1/4, 1/2) and (1/2, 1/4) lie mid-edge of the two neighbouring large cells.
    CHECK(m.num_hanging_vertices() == 2);
    const int v = m.find_vertex({TMesh::kRoot / 4, TMesh::kRoot / 2});
    REQUIRE(v >= 0);
    CHECK(m.vertex_is_hanging(v));
    const int hc = m.vertex_hanging_cell(v);
    CHECK(m.cell_size(hc) == 0.5);
    CHECK(m.cell_polygon(hc).size() == 5);
    CHECK(m.check_invariants() == "");
  }

  TEST_CASE("balance enforces 2:1 after deep local refinement") {
    TMesh m(2);
    int n = m.leaf_at_doubled(1, 1);
    for (int k = 0; k < 8; ++k) n = m.refine(n) + 3;  // always the NE child: towards (1/4,1/4)
    const std::size_t splits = m.balance();
    CHECK(splits > 0);
    m.build_topology();
    CHECK(m.check_invariants() == "");
    CHECK(m.max_level() == 10);
  }

  TEST_CASE("random refinement keeps all invariants") {
    std::mt19937 rng(7);
    TMesh m(2);
    for (int round = 0; round < 300; ++round) {
      std::uniform_int_distribution<std::int64_t> pick(0, TMesh::kRoot - 1);
      const int n = m.leaf_at_doubled(2 * pick(rng) + 1, 2 * pick(rng) + 1);
      if (m.node(n).level < 12) m.refine(n);
    }
    m.balance();
    m.build_topology();
    CHECK(m.check_invariants() == "");
    // Every hanging vertex is the midpoint of exactly one cell edge, listed by that cell.
    std::size_t listed = 0;
    for (int c = 0; c < static_cast<int>(m.num_cells()); ++c)
      for (int h : m.cell_edge_midpoints(c))
        if (h >= 0) {
          ++listed;
          CHECK(m.vertex_hanging_cell(h) == c);
        }
    CHECK(listed == m.num_hanging_vertices());
    CHECK(m.num_hanging_vertices() > 0);
  }

  TEST_CASE("unbalanced tree is detected") {
    TMesh m(1);
    int n = m.refine(m.leaf_at_doubled(1, 1));
    m.refine(n + 3);  // level-3 cells next to level-1 cells
    CHECK_THROWS_AS(m.build_topology(), tspline::InternalError);
  }

  TEST_CASE("boundary refinement meets the tolerance on every test domain") {
    for (const char* name : {"disk.txt", "flower.txt", "lshape_cw.txt", "gear.txt"}) {
      CAPTURE(name);
      const tspline::BoundaryMap b = load_boundary(name);
      TMesh m(2);
      const double tol = 1e-4;
      const auto rep = tspline::refine_to_boundary(m, b, {tol, 22});
      CHECK(rep.edges_over_tolerance == 0);
      CHECK(m.check_invariants() == "");
      // Independent check: brute force over all chain vertices of every boundary edge.
      for (int c = 0; c < static_cast<int>(m.num_cells()); ++c) {
        for (int e = 0; e < 4; ++e) {
          tspline::Side side;
          double t0, t1;
          if (!tspline::boundary_edge_params(m.node(m.cell_node(c)), static_cast<tspline::CellEdge>(e), side, t0,
                                             t1))
            continue;
          const Eigen::Vector2d a = b.point(side, t0), bb = b.point(side, t1);
          const auto& pts = b.chain_points(side);
          const auto& ts = b.chain_params(side);
          for (std::size_t k = 0; k < pts.size(); ++k) {
            if (!(ts[k] > t0 && ts[k] < t1)) continue;
            const Eigen::Vector2d u = bb - a, w = pts[k] - a;
            CHECK(0.5 * std::abs(u.x() * w.y() - u.y() * w.x()) <= tol);
          }
        }
      }
    }
  }

  TEST_CASE("boundary vertices lie on the polygon and the square is not refined") {
    const tspline::BoundaryMap b = load_boundary("square.txt");
    TMesh m(2);
    const auto rep = tspline::refine_to_boundary(m, b, {1e-12, 22});
    // The square's vertices are collinear with the cell edges: zero error, no split.
    CHECK(rep.boundary_splits == 0);
    CHECK(m.num_cells() == 16);
  }

  TEST_CASE("Coons patch reproduces the boundary and is the identity on the unit square") {
    const tspline::BoundaryMap sq = load_boundary("square.txt");
    for (double s : {0.0, 0.125, 0.3, 0.5, 0.9, 1.0})
      for (double t : {0.0, 0.2, 0.5, 0.75, 1.0}) {
        const Eigen::Vector2d x = tspline::coons_point(sq, {s, t});
        CHECK(x.x() == doctest::Approx(s).epsilon(1e-14));
        CHECK(x.y() == doctest::Approx(t).epsilon(1e-14));
      }
    const tspline::BoundaryMap disk = load_boundary("disk.txt");
    for (double s : {0.0, 0.3, 0.77, 1.0}) {
      for (const Eigen::Vector2d& uv : {Eigen::Vector2d(s, 0.0), Eigen::Vector2d(s, 1.0), Eigen::Vector2d(0.0, s),
                                       Eigen::Vector2d(1.0, s)}) {
        CHECK((tspline::coons_point(disk, uv) - disk.point_at(uv)).norm() < 1e-14);
      }
    }
  }
}
