// Real coastlines (Natural Earth 1:10m, km; tests/data/coastlines): the whole
// pipeline with default options ends with a certified map. Bali's first
// interpolating map folds (230 of 14,160 samples with det J < 0); before the
// global untangling of the map it ended with 14 elements det J < 0 (exit 3).
#include <doctest/doctest.h>

#include <string>

#include "test_support.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"

TEST_SUITE("coastlines") {
  TEST_CASE("Bali and the Isle of Man: certified valid with default options, and honest quality figures") {
    for (const std::string name : {"bali", "isle_of_man"}) {
      CAPTURE(name);
      const tspline::Polygon poly =
          tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/" + name + ".txt");
      const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, {});
      REQUIRE(r.map);
      CHECK(r.certified_valid());
      CHECK(r.boundary_simple);
      CHECK(r.boundary_problem.empty());
      // The certificate stands on its own: certify the kept map again.
      const tspline::MapCertification again = tspline::certify_map(*r.map);
      CHECK(again.certified_valid());
      CHECK(again.min_relative_lower_bound > 0.0);
      // The dense whole-map minimum is positive and not above the Gauss-point one
      // by more than the sampling can explain.
      CHECK(r.dense_quality.nonpositive_det == 0);
      CHECK(r.dense_quality.min_mean_ratio > 0.0);
      CHECK(r.dense_quality.min_mean_ratio <= r.quality.min_mean_ratio + 0.05);
      MESSAGE(name << ": " << r.map->mesh().num_cells() << " cells, " << again.elements << " elements, J_r min "
                   << r.dense_quality.min_mean_ratio << " (whole map) / " << r.quality.min_mean_ratio
                   << " (Gauss), det J >= " << again.min_relative_lower_bound << " x element mean");
    }
  }
}
