// The front half on every bundled test domain, with default options and
// automatic corners: the optimized T-mesh must have no inverted cell.
#include <doctest/doctest.h>

#include <iostream>

#include "tspline/io/polygon_reader.h"
#include "tspline/parameterization.h"

TEST_SUITE("parameterization") {
  TEST_CASE("every test domain ends with zero inverted cells (default options, automatic corners)") {
    for (const std::string name : {"square.txt", "lshape_cw.txt", "disk.txt", "flower.txt", "cshape.txt", "gear.txt",
                             "blob_bay.txt", "fjords.txt"}) {
      CAPTURE(name);
      const auto poly = tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/polygons/" + name);
      const tspline::FrontResult r = tspline::run_front(poly, {});
      MESSAGE(name << ": " << r.mesh.num_cells() << " cells, inverted after Coons "
                   << r.quality_coons.inverted_cells << ", after optimization " << r.quality_optimized.inverted_cells
                   << ", min/mean quality " << r.quality_optimized.min_quality << "/"
                   << r.quality_optimized.mean_quality << ", sweeps " << r.total_sweeps << ", repair rounds " << r.repair_refined_cells.size());
      CHECK(r.quality_optimized.inverted_cells == 0);
      CHECK(r.refinement.edges_over_tolerance == 0);
      CHECK(r.mesh.check_invariants() == "");
      CHECK(r.quality_optimized.min_quality > 0.0);
      // Optimization never makes the mesh worse than the Coons start.
      CHECK(r.quality_optimized.mean_quality >= r.quality_coons.mean_quality - 1e-12);
      // Boundary vertices stay exactly where the chord-length map puts them.
      for (int v = 0; v < static_cast<int>(r.mesh.num_vertices()); ++v)
        if (r.mesh.vertex_on_boundary(v))
          CHECK((r.optimized[v] - r.boundary.point_at(r.mesh.vertex_param(v))).norm() == 0.0);
    }
  }
}
