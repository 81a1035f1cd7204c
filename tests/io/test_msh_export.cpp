// Curved-element export (`tspline export --msh`): Gmsh reads the MSH 4.1 file
// back through its API, the element type is 36 with Gmsh's own node order, and
// every node of every element lies on the T-spline map at the equispaced
// parametric position of its Bezier element.
#include <doctest/doctest.h>
#include <gmsh.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "meshopt/gmsh/gmsh_mesh.h"
#include "test_support.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/io/msh_export.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/multipatch/multipatch_parameterization.h"

namespace fs = std::filesystem;

TEST_SUITE("msh_export") {
  TEST_CASE("Gmsh reads the bicubic quadrilaterals back and their nodes lie on the map") {
    const fs::path d = test_support::scratch_dir("msh_export", "flower");
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("flower.txt"));
    const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, {});
    REQUIRE(r.map.has_value());
    REQUIRE(r.map->mesh().num_hanging_vertices() > 0);
    const tspline::TSplineMap& map = *r.map;
    const fs::path file = d / "flower.msh";
    const tspline::io::MshExportStats stats = tspline::io::write_msh_file(file.string(), map);
    const tspline::BezierExtraction extraction(map.basis());
    const auto& elements = extraction.elements();
    CHECK(stats.elements == elements.size());
    // Shared nodes: fewer than 16 per element (elements with a common edge share it).
    CHECK(stats.nodes < 16 * stats.elements);
    double diameter = 0.0;
    for (const auto& v : poly.vertices)
      for (const auto& w : poly.vertices) diameter = std::max(diameter, (v - w).norm());

    meshopt::gmsh_io::Session session;
    gmsh::open(file.string());
    // Gmsh's own description of type 36: 16 nodes, order 3, reference square [-1,1]^2.
    std::string name;
    int dim = 0, order = 0, num_nodes = 0, num_primary = 0;
    std::vector<double> local;
    gmsh::model::mesh::getElementProperties(36, name, dim, order, num_nodes, local, num_primary);
    CHECK(dim == 2);
    CHECK(order == 3);
    REQUIRE(num_nodes == 16);
    REQUIRE(local.size() == 32);
    for (int k = 0; k < 16; ++k) {
      CAPTURE(k);
      CHECK((local[2 * k] + 1) / 2 == doctest::Approx(tspline::io::kQua16Local[k][0]).epsilon(1e-15));
      CHECK((local[2 * k + 1] + 1) / 2 == doctest::Approx(tspline::io::kQua16Local[k][1]).epsilon(1e-15));
    }
    // Elements and nodes as Gmsh read them.
    std::vector<std::size_t> tags, conn;
    gmsh::model::mesh::getElementsByType(36, tags, conn);
    REQUIRE(tags.size() == elements.size());
    std::vector<std::size_t> node_tags;
    std::vector<double> coord, param;
    gmsh::model::mesh::getNodes(node_tags, coord, param);
    CHECK(node_tags.size() == stats.nodes);
    std::map<std::size_t, Eigen::Vector2d> node;
    for (std::size_t i = 0; i < node_tags.size(); ++i) node[node_tags[i]] = {coord[3 * i], coord[3 * i + 1]};
    double worst = 0.0;
    for (std::size_t i = 0; i < tags.size(); ++i) {
      const tspline::BezierElement& e = elements[tags[i] - 1];
      for (int k = 0; k < 16; ++k) {
        const Eigen::Vector2d st((local[2 * k] + 1) / 2, (local[2 * k + 1] + 1) / 2);
        const Eigen::Vector2d uv = e.lo + st.cwiseProduct(e.hi - e.lo);
        worst = std::max(worst, (node.at(conn[16 * i + k]) - map.point(uv)).norm() / diameter);
      }
    }
    // Gmsh's Lagrange geometry: det J > 0 at its Gauss points (orientation kept)
    // and close to the map there (the interpolation error, not round-off).
    std::vector<double> gauss, weights, jac, det, pts;
    gmsh::model::mesh::getIntegrationPoints(36, "Gauss4", gauss, weights);
    gmsh::model::mesh::getJacobians(36, gauss, jac, det, pts);
    const std::size_t ng = gauss.size() / 3;
    REQUIRE(det.size() == ng * tags.size());
    double min_det = det[0], worst_interior = 0.0;
    for (std::size_t i = 0; i < tags.size(); ++i) {
      const tspline::BezierElement& e = elements[tags[i] - 1];
      for (std::size_t g = 0; g < ng; ++g) {
        min_det = std::min(min_det, det[i * ng + g]);
        const Eigen::Vector2d st((gauss[3 * g] + 1) / 2, (gauss[3 * g + 1] + 1) / 2);
        const Eigen::Vector2d x(pts[3 * (i * ng + g)], pts[3 * (i * ng + g) + 1]);
        worst_interior = std::max(worst_interior, (x - map.point(e.lo + st.cwiseProduct(e.hi - e.lo))).norm() / diameter);
      }
    }
    // No two nodes at the same point (Gmsh's own check merges them).
    gmsh::model::mesh::removeDuplicateNodes();
    std::vector<std::size_t> after;
    gmsh::model::mesh::getNodes(after, coord, param);
    CHECK(after.size() == node_tags.size());
    gmsh::clear();
    MESSAGE("flower: " << tags.size() << " type-36 elements, " << stats.nodes << " nodes; max |node - S| / diameter "
                       << worst << "; Lagrange geometry vs S at Gauss points: " << worst_interior
                       << " of the diameter; min det J " << min_det);
    CHECK(worst <= 1e-12);
    CHECK(min_det > 0.0);
    CHECK(worst_interior < 1e-3);
    CHECK(worst_interior > 1e-12);  // the elements only interpolate the rational map
  }

  TEST_CASE("multi-patch map: one surface per patch, nodes shared along every cut, no duplicates") {
    const fs::path d = test_support::scratch_dir("msh_export", "plate");
    const auto rings = tspline::io::read_text_rings(std::string(TSPLINE_TEST_DATA_DIR) + "/holes/plate_with_hole.txt");
    const tspline::Domain dom{rings.front(), {rings.begin() + 1, rings.end()}};
    const tspline::MultiPatchResult R = tspline::run_multipatch_parameterization(dom, std::nullopt, {}, {});
    REQUIRE(R.certified_valid());
    std::vector<const tspline::TSplineMap*> maps;
    std::size_t elements = 0;
    for (const auto& r : R.patches) {
      maps.push_back(&*r.map);
      elements += tspline::BezierExtraction(r.map->basis()).elements().size();
    }
    std::size_t alone = 0;  // nodes of the patches exported one by one
    for (const tspline::TSplineMap* m : maps) {
      tspline::io::MshExportStats s;
      (void)tspline::io::msh_document(*m, &s);
      alone += s.nodes;
    }
    const fs::path file = d / "plate.msh";
    const tspline::io::MshExportStats stats = tspline::io::write_msh_file(file.string(), maps, R.layout.interfaces);
    CHECK(stats.elements == elements);
    // Shared interface nodes: every cut's nodes once (the shared knots make
    // the positions correspond), so fewer nodes than the patches alone have.
    std::size_t cut_nodes = 0;
    for (const tspline::Interface& f : R.layout.interfaces) {
      const tspline::BezierExtraction ex(maps[f.patch_a]->basis());
      std::set<double> ends;
      for (const tspline::BezierElement& e : ex.elements()) {
        const Eigen::Vector2d lo = e.lo, hi = e.hi;
        switch (f.side_a) {
          case 0: if (lo.y() == 0) ends.insert(lo.x()), ends.insert(hi.x()); break;
          case 1: if (hi.x() == 1) ends.insert(lo.y()), ends.insert(hi.y()); break;
          case 2: if (hi.y() == 1) ends.insert(lo.x()), ends.insert(hi.x()); break;
          default: if (lo.x() == 0) ends.insert(lo.y()), ends.insert(hi.y()); break;
        }
      }
      cut_nodes += 3 * (ends.size() - 1) + 1;
    }
    CHECK(stats.nodes == alone - cut_nodes);
    meshopt::gmsh_io::Session session;
    gmsh::open(file.string());
    std::vector<std::pair<int, int>> surfaces;
    gmsh::model::getEntities(surfaces, 2);
    CHECK(surfaces.size() == R.patches.size());
    std::vector<std::pair<int, int>> groups;
    gmsh::model::getPhysicalGroups(groups, 2);
    CHECK(groups.size() == R.patches.size() + 1);
    std::vector<std::size_t> node_tags;
    std::vector<double> coord, param;
    gmsh::model::mesh::getNodes(node_tags, coord, param);
    CHECK(node_tags.size() == stats.nodes);
    std::vector<std::size_t> tags, conn;
    gmsh::model::mesh::getElementsByType(36, tags, conn);
    CHECK(tags.size() == elements);
    // Conforming across the cuts: Gmsh finds no two nodes at one point.
    gmsh::model::mesh::removeDuplicateNodes();
    std::vector<std::size_t> after;
    gmsh::model::mesh::getNodes(after, coord, param);
    CHECK(after.size() == node_tags.size());
    // Patch 0's elements: its nodes lie on its map.
    std::map<std::size_t, Eigen::Vector2d> node;
    gmsh::model::mesh::getNodes(node_tags, coord, param);
    for (std::size_t i = 0; i < node_tags.size(); ++i) node[node_tags[i]] = {coord[3 * i], coord[3 * i + 1]};
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> etags, enodes;
    gmsh::model::mesh::getElements(types, etags, enodes, 2, 1);
    REQUIRE(types.size() == 1);
    const tspline::BezierExtraction ex0(maps[0]->basis());
    REQUIRE(etags[0].size() == ex0.elements().size());
    double worst = 0.0;
    for (std::size_t i = 0; i < etags[0].size(); ++i)
      for (int k = 0; k < 16; ++k) {
        const tspline::BezierElement& e = ex0.elements()[i];
        const Eigen::Vector2d st(tspline::io::kQua16Local[k][0], tspline::io::kQua16Local[k][1]);
        worst = std::max(worst, (node.at(enodes[0][16 * i + k]) - maps[0]->point(e.lo + st.cwiseProduct(e.hi - e.lo))).norm());
      }
    CHECK(worst <= 1e-12 * R.diameter);
    gmsh::clear();
    MESSAGE("plate: " << R.patches.size() << " patches, " << elements << " elements, " << stats.nodes
                      << " nodes (" << alone << " for the patches alone)");
  }

  TEST_CASE("tspline export --msh: file and bad input") {
    const fs::path d = test_support::scratch_dir("msh_export", "app");
    const fs::path map = test_support::param_polygon("disk.txt", d / "disk");
    const fs::path out = d / "disk.msh";
    const auto r = test_support::require_success(
        test_support::run_app("export " + test_support::quoted(map) + " --msh " + test_support::quoted(out), d));
    CHECK(test_support::contains(r.out, "Gmsh type 36"));
    const std::string text = test_support::slurp(out);
    CHECK(text.rfind("$MeshFormat\n4.1 0 8\n", 0) == 0);
    CHECK(test_support::contains(text, "\n2 1 36 "));
    // Neither output: one error line, exit 1.
    const auto none = test_support::run_app("export " + test_support::quoted(map), d);
    CHECK(none.exit_code == 1);
    CHECK(test_support::count_lines(none.err) == 1);
    // A map that does not exist: exit 2, one line naming it.
    test_support::check_bad_invocation(
        {"export " + test_support::quoted(d / "nonesuch.json") + " --msh " + test_support::quoted(d / "x.msh"),
         "nonesuch.json", 2},
        d);
    CHECK(!fs::exists(d / "x.msh"));
  }
}
