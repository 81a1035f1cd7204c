// surface.vtu of a map (param_output.h, cell_grid.h): every T-mesh cell as
// k x k quads on its parametric grid, cells that meet sharing their points.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "coastline_maps.h"
#include "tspline/io/cell_grid.h"
#include "tspline/io/param_output.h"
#include "tspline/validity/map_quality.h"

TEST_SUITE("surface_vtu") {
  TEST_CASE(
      "one point per parametric grid position, each the map's image there, the quads on their cells' grids") {
    const tspline::ParameterizationResult r = test_support::isle_of_man_map();
    REQUIRE(r.map);
    const tspline::TMesh& mesh = r.map->mesh();
    REQUIRE(mesh.num_cells() > 100);
    bool hanging = false;
    for (int v = 0; v < static_cast<int>(mesh.num_vertices()); ++v)
      hanging = hanging || mesh.vertex_is_hanging(v);
    REQUIRE(hanging);  // cells of different sizes meet
    for (const int k : {1, 2, 3, 4}) {
      CAPTURE(k);
      const toolkit::io::VtuMesh s = tspline::io::surface_vtu(*r.map, k);
      const std::vector<Eigen::Vector2d>& uv = s.point_vectors.at("parametric");
      REQUIRE(uv.size() == s.points.size());
      // Every grid position of every cell, computed here: as many points as
      // distinct positions (shared, none twice).
      std::set<std::pair<double, double>> positions;
      for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
        const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
        for (int j = 0; j <= k; ++j)
          for (int i = 0; i <= k; ++i)
            positions.insert({lo.x() + (hi.x() - lo.x()) * i / k, lo.y() + (hi.y() - lo.y()) * j / k});
      }
      CHECK(s.points.size() == positions.size());
      CHECK(s.points.size() < mesh.num_cells() * static_cast<std::size_t>((k + 1) * (k + 1)));
      std::set<std::pair<double, double>> seen;
      for (const Eigen::Vector2d& p : uv) seen.insert({p.x(), p.y()});
      CHECK(seen.size() == uv.size());
      // Each quad on its cell's grid, counter-clockwise in the parameter plane.
      REQUIRE(s.cells.size() == mesh.num_cells() * static_cast<std::size_t>(k * k));
      const std::vector<int>& cell = s.cell_ints.at("cell");
      std::size_t off_grid = 0;
      for (std::size_t q = 0; q < s.cells.size(); ++q) {
        const int c = cell[q];
        const int i = static_cast<int>(q % static_cast<std::size_t>(k * k)) % k;
        const int j = static_cast<int>(q % static_cast<std::size_t>(k * k)) / k;
        const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
        auto at = [&](int a, int b) {
          return Eigen::Vector2d(lo.x() + (hi.x() - lo.x()) * a / k, lo.y() + (hi.y() - lo.y()) * b / k);
        };
        const std::vector<int>& v = s.cells[q];
        REQUIRE(v.size() == 4);
        off_grid += uv[v[0]] != at(i, j) || uv[v[1]] != at(i + 1, j) || uv[v[2]] != at(i + 1, j + 1) ||
                    uv[v[3]] != at(i, j + 1);
      }
      CHECK(off_grid == 0);
      // The points and their figures are the map's at their parametric positions
      // (whichever cell sampled them: the map is continuous).
      const std::vector<double>& det = s.point_scalars.at("det_jacobian");
      double worst_point = 0.0, worst_det = 0.0, det_scale = 0.0;
      for (std::size_t p = 0; p < uv.size(); ++p) {
        worst_point = std::max(worst_point, (r.map->point(uv[p]) - s.points[p]).norm());
        const double d = r.map->jacobian(uv[p]).determinant();
        worst_det = std::max(worst_det, std::abs(d - det[p]));
        det_scale = std::max(det_scale, std::abs(d));
      }
      CHECK(worst_point <= 1e-12 * 100.0);  // the island is some 50 km across
      CHECK(worst_det <= 1e-10 * det_scale);
    }
  }

  TEST_CASE("cell_grid_vtu samples each point once, in the order of its first cell") {
    const tspline::ParameterizationResult r = test_support::isle_of_man_map();
    REQUIRE(r.map);
    const tspline::TMesh& mesh = r.map->mesh();
    std::vector<std::pair<int, Eigen::Vector2d>> calls;
    const toolkit::io::VtuMesh g = tspline::io::cell_grid_vtu(mesh, 2, [&](int c, const Eigen::Vector2d& uv) {
      calls.push_back({c, uv});
      return uv;
    });
    REQUIRE(calls.size() == g.points.size());
    std::map<std::pair<double, double>, int> first_cell;
    for (const auto& [c, uv] : calls) {
      CHECK(first_cell.emplace(std::make_pair(uv.x(), uv.y()), c).second);
      CHECK(uv.x() >= mesh.cell_min(c).x());
      CHECK(uv.x() <= mesh.cell_max(c).x());
      CHECK(uv.y() >= mesh.cell_min(c).y());
      CHECK(uv.y() <= mesh.cell_max(c).y());
    }
    // Cells in order: the sampling cells never decrease.
    CHECK(std::is_sorted(calls.begin(), calls.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; }));
    CHECK(g.points.size() <= tspline::io::cell_grid_point_estimate(mesh, 2) + mesh.num_vertices());
    CHECK_THROWS_AS(tspline::io::cell_grid_vtu(mesh, 0, [](int, const Eigen::Vector2d& uv) { return uv; }),
                    std::invalid_argument);
  }
}
