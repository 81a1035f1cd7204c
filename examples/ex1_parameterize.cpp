// Example 1: parameterize a polygon.
//
//   example_parameterize [POLYGON] [OUTDIR]      (defaults: tests/data/polygons/flower.txt, out/ex1)
//
// The whole pipeline of the toolkit in one call: the polygon's boundary is
// validated, four corners are chosen and the boundary is mapped by chord length
// onto the sides of the unit square; a balanced quadtree T-mesh adapted to the
// boundary is built, started as a Coons patch, untangled and smoothed; a cubic
// T-spline interpolates its vertices; the map's mean ratio Jacobian is checked
// at Gauss points and the poor cells are refined until the map is valid and
// good. We then write the same files as `tspline param` and report the quality.
#include <cstdio>
#include <exception>
#include <string>

#include "tspline/pipeline/adaptive_parameterization.h"  // run_parameterization
#include "tspline/io/param_output.h"            // param_report, write_param_outputs
#include "tspline/io/polygon_reader.h"          // read_polygon (text or GeoJSON)

int run(int argc, char** argv) {
  const std::string input = argc > 1 ? argv[1] : TSPLINE_DATA_DIR "/polygons/flower.txt";
  const std::string out = argc > 2 ? argv[2] : "out/ex1";

  // 1. Read the polygon: one "x y" pair per line ('#' starts a comment). The
  //    reader rejects empty files, NaN, repeated vertices, ... with an
  //    InputError that names the line.
  const tspline::Polygon polygon = tspline::io::read_polygon(input);

  // 2. Options. The defaults are those of `tspline param`: automatic corners,
  //    boundary tolerance 1e-5 x (bounding-box diagonal)^2, initial level 3.
  //    The adaptive options hold delta of Sect. 6.2: cells whose mean ratio
  //    Jacobian J_r = 2 det J / |J|_F^2 falls below it are refined.
  tspline::ParameterizationOptions options;
  tspline::AdaptiveOptions adaptive;
  adaptive.min_jacobian = 0.2;

  // 3. Run. The result holds the T-mesh, the T-spline map (result.map) and its
  //    quality at the 4x4 Gauss points of every cell.
  const tspline::ParameterizationResult result = tspline::run_parameterization(polygon, options, adaptive);

  // 4. Write tspline.json, the ParaView files and report.json (atomically).
  tspline::io::write_param_outputs(result, out, tspline::io::param_report(result, input), 4);

  std::printf("cells %zu\nfunctions %zu\nvalid %d\nmin_jr %.6f\nmean_jr %.6f\n", result.map->mesh().num_cells(),
              result.map->basis().size(), result.valid() ? 1 : 0, result.quality.min_mean_ratio,
              result.quality.mean_mean_ratio);
  // A valid map has det J > 0 at every Gauss point; "good" also has J_r >= delta.
  return result.good() ? 0 : 1;
}

// Library errors are exceptions with a message that names the problem:
// tspline::InputError (bad input or options), tspline::IoError (files),
// tspline::NumericalError (e.g. a singular system); libmeshopt throws the same
// InputError (toolkit/errors.h, one header for all libraries).
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
