#pragma once
// Maps of bundled coastlines that several suites read (one patch, default
// options): made by the pipeline itself, so each test sees today's map.
#include <string>

#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/adaptive_parameterization.h"

namespace test_support {

/// The Isle of Man (tests/data/coastlines/isle_of_man.txt, km): 400 cells,
/// hanging vertices, certified.
inline tspline::ParameterizationResult isle_of_man_map() {
  const tspline::Polygon p =
      tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/isle_of_man.txt");
  return tspline::run_parameterization(p, {}, {});
}

}  // namespace test_support
