// surface_bezier.vtu (bezier_vtu.h): the map as rational bicubic Bezier cells
// of VTK 9, read back through VTK's own XML reader and evaluated by VTK's own
// cells (vtkBezierQuadrilateral with the file's RationalWeights and
// HigherOrderDegrees): equal to the T-spline map at random points to
// round-off, on T-meshes whose weights are not constant; the point data equal
// J_r at each element's 4 x 4 equispaced points; the cell data `certified`
// agrees with certify_map; `tspline param` and `tspline export --vtk-bezier`
// write it for every patch.
#include <doctest/doctest.h>
#include <vtkCell.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkGenericCell.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "separable_maps.h"  // (before perturbed_map.h, which uses it)

#include "perturbed_map.h"
#include "test_support.h"
#include "toolkit/io/vtu_writer.h"
#include "tspline/io/bezier_vtu.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"

namespace fs = std::filesystem;

namespace {

vtkSmartPointer<vtkUnstructuredGrid> read_back(const fs::path& file) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(file.string().c_str());
  reader->Update();
  return reader->GetOutput();
}

/// VTK's evaluation of cell c at local (s, t): the position and the interpolation weights.
Eigen::Vector2d vtk_point(vtkUnstructuredGrid* g, vtkGenericCell* cell, vtkIdType c, double s, double t,
                          std::vector<double>& weights) {
  g->GetCell(c, cell);
  double pc[3] = {s, t, 0.0}, x[3];
  int sub = 0;
  weights.assign(static_cast<std::size_t>(cell->GetNumberOfPoints()), 0.0);
  cell->EvaluateLocation(sub, pc, x, weights.data());
  return {x[0], x[1]};
}

/// A point array of cell c interpolated with VTK's weights.
double interpolate(vtkUnstructuredGrid* g, vtkGenericCell* cell, const char* name,
                   const std::vector<double>& weights) {
  vtkDataArray* a = g->GetPointData()->GetArray(name);
  double v = 0.0;
  for (vtkIdType k = 0; k < cell->GetNumberOfPoints(); ++k)
    v += weights[k] * a->GetTuple1(cell->GetPointId(k));
  return v;
}

struct CellCheck {
  double max_position_error = 0.0;     ///< / diameter, at random points
  double max_jr_error_at_nodes = 0.0;  ///< at the 4 x 4 equispaced points
  double max_jr_error_between = 0.0;   ///< at random points
};

/// Every cell of the file against `map` (cells of patch `patch` only, if the file has several).
CellCheck check_cells(vtkUnstructuredGrid* g, const tspline::TSplineMap& map, int patch, double diameter) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  vtkNew<vtkGenericCell> cell;
  std::vector<double> w;
  CellCheck out;
  vtkDataArray* lo = g->GetCellData()->GetArray("parametric_lo");
  vtkDataArray* hi = g->GetCellData()->GetArray("parametric_hi");
  vtkDataArray* patches = g->GetCellData()->GetArray("patch");
  REQUIRE(lo);
  REQUIRE(hi);
  REQUIRE(patches);
  for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c) {
    if (static_cast<int>(patches->GetTuple1(c)) != patch) continue;
    REQUIRE(g->GetCellType(c) == VTK_BEZIER_QUADRILATERAL);
    const Eigen::Vector2d a(lo->GetTuple3(c)[0], lo->GetTuple3(c)[1]);
    const Eigen::Vector2d b(hi->GetTuple3(c)[0], hi->GetTuple3(c)[1]);
    auto uv_of = [&](double s, double t) {
      return Eigen::Vector2d(a + Eigen::Vector2d(s, t).cwiseProduct(b - a));
    };
    for (int k = 0; k < 4; ++k) {
      const double s = u01(rng), t = u01(rng);
      const Eigen::Vector2d x = vtk_point(g, cell, c, s, t, w);
      out.max_position_error =
          std::max(out.max_position_error, (x - map.point(uv_of(s, t))).norm() / diameter);
      const double jr = tspline::mean_ratio_jacobian(map.derivatives(uv_of(s, t), 1, -1).J);
      out.max_jr_error_between =
          std::max(out.max_jr_error_between, std::abs(interpolate(g, cell, "mean_ratio_jacobian", w) - jr));
    }
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        vtk_point(g, cell, c, i / 3.0, j / 3.0, w);
        // The element's own polynomial at its border (one-sided), as the file was made.
        const double jr = tspline::mean_ratio_jacobian(
            map.derivatives(uv_of(i / 3.0, j / 3.0), 1,
                            static_cast<int>(g->GetCellData()->GetArray("cell")->GetTuple1(c)))
                .J);
        out.max_jr_error_at_nodes = std::max(out.max_jr_error_at_nodes,
                                             std::abs(interpolate(g, cell, "mean_ratio_jacobian", w) - jr));
      }
  }
  return out;
}

}  // namespace

TEST_SUITE("bezier_vtu") {
  TEST_CASE("the 16 points of a bicubic cell in VTK's order: corners, edges, interior") {
    std::set<int> seen;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) seen.insert(tspline::io::vtk_bezier_quad_index(i, j));
    CHECK(seen.size() == 16);
    CHECK(*seen.begin() == 0);
    CHECK(*seen.rbegin() == 15);
    CHECK(tspline::io::vtk_bezier_quad_index(0, 0) == 0);
    CHECK(tspline::io::vtk_bezier_quad_index(3, 0) == 1);
    CHECK(tspline::io::vtk_bezier_quad_index(3, 3) == 2);
    CHECK(tspline::io::vtk_bezier_quad_index(0, 3) == 3);
  }

  TEST_CASE("VTK's rational Bezier cells are the T-spline map: positions to round-off, J_r at the nodes") {
    const fs::path d = test_support::scratch_dir("bezier_vtu", "perturbed");
    // T-junctions: knot lines cross cells, the weights of the Bezier points vary.
    const tspline::TSplineMap map = test_support::perturbed_map(3, 0.03);
    REQUIRE(map.mesh().num_hanging_vertices() > 0);
    const toolkit::io::VtuMesh mesh = tspline::io::bezier_vtu(map);
    const std::vector<double>& wts = mesh.point_scalars.at("RationalWeights");
    CHECK(*std::max_element(wts.begin(), wts.end()) - *std::min_element(wts.begin(), wts.end()) > 1e-3);
    CHECK(mesh.cells.size() > map.mesh().num_cells());  // cells split by knot lines
    toolkit::io::write_vtu((d / "cells.vtu").string(), mesh);
    const vtkSmartPointer<vtkUnstructuredGrid> g = read_back(d / "cells.vtu");
    REQUIRE(g->GetNumberOfCells() == static_cast<vtkIdType>(mesh.cells.size()));
    REQUIRE(g->GetPointData()->GetRationalWeights() != nullptr);
    REQUIRE(g->GetCellData()->GetHigherOrderDegrees() != nullptr);
    CHECK(g->GetCellData()->GetHigherOrderDegrees()->GetTuple3(0)[0] == 3);
    const CellCheck r = check_cells(g, map, 0, 10.0 * std::sqrt(2.0));
    MESSAGE("max |S_vtk - S| / diameter " << r.max_position_error << "; J_r: at the nodes "
                                          << r.max_jr_error_at_nodes << ", between "
                                          << r.max_jr_error_between);
    CHECK(r.max_position_error <= 1e-12);
    CHECK(r.max_jr_error_at_nodes <= 1e-12);
    CHECK(r.max_jr_error_between <= 0.05);  // an interpolant of J_r, not J_r itself
  }

  TEST_CASE("cell data `certified` is certify_map's verdict, element by element") {
    const tspline::TSplineMap map = test_support::perturbed_map(7, 0.35);  // folds
    const tspline::MapCertification c = tspline::certify_map(map);
    REQUIRE(!c.failures.empty());
    for (const tspline::MapCertification* given :
         {static_cast<const tspline::MapCertification*>(nullptr), &c}) {
      const toolkit::io::VtuMesh mesh = tspline::io::bezier_vtu(map, given);
      const std::vector<int>& certified = mesh.cell_ints.at("certified");
      REQUIRE(certified.size() == c.elements);
      CHECK(static_cast<std::size_t>(std::count(certified.begin(), certified.end(), 0)) == c.failures.size());
      for (const tspline::CertificationFailure& f : c.failures) CHECK(certified[f.element] == 0);
    }
  }

  TEST_CASE(
      "tspline param writes surface_bezier.vtu for every patch; tspline export --vtk-bezier the same cells") {
    const fs::path d = test_support::scratch_dir("bezier_vtu", "app");
    const auto p = test_support::run_app(
        "param " + test_support::quoted(fs::path(TSPLINE_TEST_DATA_DIR) / "holes" / "plate_with_hole.txt") +
            " -q --out " + test_support::quoted(d / "plate"),
        d);
    CAPTURE(p.err);
    REQUIRE(p.exit_code == 0);
    const tspline::io::LoadedMaps maps = tspline::io::read_maps_file((d / "plate" / "tspline.json").string());
    REQUIRE(maps.patches.size() >= 2);
    const auto e = test_support::run_app("export " + test_support::quoted(d / "plate" / "tspline.json") +
                                             " --vtk-bezier " + test_support::quoted(d / "exported.vtu") +
                                             " --vtu-compression none",
                                         d);
    CAPTURE(e.err);
    REQUIRE(e.exit_code == 0);
    CHECK(test_support::contains(e.out, "Bezier cells"));
    // The arrays raw, as asked (param's files LZ4-compressed, the default).
    const std::string exported = test_support::slurp(d / "exported.vtu");
    CHECK(exported.substr(0, exported.find("<AppendedData")).find("compressor=") == std::string::npos);
    for (const char* file : {"plate/surface_bezier.vtu", "exported.vtu"}) {
      CAPTURE(file);
      const vtkSmartPointer<vtkUnstructuredGrid> g = read_back(d / file);
      std::size_t elements = 0;
      for (std::size_t q = 0; q < maps.patches.size(); ++q) {
        elements += tspline::BezierExtraction(maps.patches[q].map.basis()).elements().size();
        CHECK(check_cells(g, maps.patches[q].map, static_cast<int>(q), 4.0 * std::sqrt(2.0))
                  .max_position_error <= 1e-12);
      }
      CHECK(g->GetNumberOfCells() == static_cast<vtkIdType>(elements));
      vtkDataArray* certified = g->GetCellData()->GetArray("certified");
      REQUIRE(certified);
      CHECK(certified->GetRange()[0] == 1.0);  // a certified map: every element
    }
    const auto bad = test_support::run_app("export " + test_support::quoted(d / "nonesuch.json") +
                                               " --vtk-bezier " + test_support::quoted(d / "x.vtu"),
                                           d);
    CHECK(bad.exit_code == 2);
    CHECK(!fs::exists(d / "x.vtu"));
  }
}
