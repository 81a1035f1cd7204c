// physical_tmesh.vtu of a map: each T-mesh cell drawn through the map, its cell
// data what the certificate says (param_output.h), read back with VTK.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "coastline_maps.h"
#include "test_support.h"
#include "toolkit/io/vtu_reader.h"
#include "tspline/io/front_output.h"
#include "tspline/io/param_output.h"

TEST_SUITE("physical_tmesh") {
  TEST_CASE("a certified map: every cell drawn through the map, none flagged invalid, one VTK cell per T-mesh cell") {
    const tspline::ParameterizationResult r = test_support::isle_of_man_map();
    REQUIRE(r.map);
    REQUIRE(r.certified_valid());
    const tspline::TMesh& mesh = r.map->mesh();
    const int k = 4;
    const auto dir = test_support::scratch_dir("physical_tmesh", "iom");
    tspline::io::write_param_outputs(r, dir.string(), tspline::io::param_report(r, "isle_of_man.txt"), k);
    const toolkit::io::VtuMesh m = toolkit::io::read_vtu((dir / "physical_tmesh.vtu").string());
    REQUIRE(m.cells.size() == mesh.num_cells());
    const std::vector<double>& valid = m.cell_scalars.at("valid");
    const std::vector<double>& certified = m.cell_scalars.at("certified");
    const std::vector<double>& lower = m.cell_scalars.at("det_lower_bound");
    const std::vector<double>& relative = m.cell_scalars.at("relative_det_lower_bound");
    std::size_t flagged = 0, samples = 0;
    for (std::size_t c = 0; c < m.cells.size(); ++c) {
      flagged += valid[c] != 1.0;
      CHECK(certified[c] == 1.0);
      CHECK(lower[c] > 0.0);
      CHECK(relative[c] > 0.0);
      // k points per elementary edge of the cell (hanging vertices included).
      CHECK(m.cells[c].size() == k * mesh.cell_polygon(static_cast<int>(c)).size());
      samples += m.cells[c].size();
    }
    CHECK(flagged == 0);
    // The smallest per-cell bound is the certificate's minimum over elements.
    double min_lower = lower.front(), min_relative = relative.front();
    for (std::size_t c = 0; c < lower.size(); ++c)
      min_lower = std::min(min_lower, lower[c]), min_relative = std::min(min_relative, relative[c]);
    CHECK(min_lower == r.certification.min_det_lower_bound);
    CHECK(min_relative == r.certification.min_relative_lower_bound);
    // Every point is the map's image of its parametric position (the edges are
    // drawn through the map, not as chords), and neighbours share their points.
    const toolkit::io::VtuMesh direct = tspline::io::physical_tmesh_vtu(r, k);
    REQUIRE(direct.points.size() == m.points.size());
    CHECK(m.points.size() < samples);
    double worst = 0.0;
    for (std::size_t i = 0; i < direct.points.size(); ++i) {
      const Eigen::Vector2d uv = direct.point_vectors.at("parametric")[i];
      worst = std::max(worst, (r.map->point(uv) - direct.points[i]).norm());
      CHECK(m.points[i] == direct.points[i]);
    }
    CHECK(worst <= 1e-12 * 100.0);  // the island is some 50 km across
    // The straight-chord drawing that this file used to be flags cells that
    // the certificate proves valid.
    std::vector<Eigen::Vector2d> images(mesh.num_vertices());
    for (int v = 0; v < static_cast<int>(images.size()); ++v) images[v] = r.map->point(mesh.vertex_param(v));
    const toolkit::io::VtuMesh chords = tspline::io::tmesh_vtu(mesh, images);
    std::size_t chord_flagged = 0;
    for (int v : chords.cell_ints.at("valid")) chord_flagged += v == 0;
    MESSAGE("Isle of Man: " << mesh.num_cells() << " cells, " << chord_flagged
                            << " flagged invalid by the straight-chord test, 0 by the certificate");
  }

  TEST_CASE("without a certificate: valid from the quadrature points, certified -1, bounds NaN") {
    const tspline::ParameterizationResult r = test_support::isle_of_man_map();
    REQUIRE(r.map);
    const std::size_t nc = r.map->mesh().num_cells();
    const toolkit::io::VtuMesh q = tspline::io::physical_tmesh_vtu(*r.map, 2, nullptr, {}, &r.cell_quality);
    REQUIRE(q.cells.size() == nc);
    for (std::size_t c = 0; c < nc; ++c) {
      CHECK(q.cell_ints.at("certified")[c] == -1);
      CHECK(q.cell_ints.at("valid")[c] == (r.cell_quality[c].min_det > 0 ? 1 : 0));
      CHECK(std::isnan(q.cell_scalars.at("det_lower_bound")[c]));
      CHECK(q.cell_scalars.at("min_det_jacobian")[c] == r.cell_quality[c].min_det);
    }
    const toolkit::io::VtuMesh none = tspline::io::physical_tmesh_vtu(*r.map, 1, nullptr, {}, nullptr);
    CHECK(none.cell_ints.at("valid").front() == -1);
    CHECK(none.cells.front().size() == r.map->mesh().cell_polygon(0).size());  // k = 1: the vertices only
    CHECK_THROWS_AS(tspline::io::physical_tmesh_vtu(*r.map, 0, nullptr, {}, nullptr), std::invalid_argument);
  }
}
