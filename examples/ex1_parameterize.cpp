// Example 1: parameterize a polygon, one pipeline step per call.
//
//   example_parameterize [POLYGON] [OUTDIR]      (defaults: tests/data/polygons/flower.txt, out/ex1)
//
// Sample runs:
//   example_parameterize                                   the flower (120 vertices)
//   example_parameterize tests/data/polygons/lshape_cw.txt out/lshape
//   example_parameterize tests/data/coastlines/bali.txt out/bali      (a real coastline, km)
//
// Steps 1-8 are the pipeline of the toolkit written out, each a single call to
// the library, with what it gives printed after it; step 9 is the same pipeline
// in one call (run_parameterization), which adds what a hand-written sequence
// leaves out: several corner choices tried, nested coarse-to-fine optimization,
// repair of inverted cells, and adaptive refinement until det J > 0 is
// certified. Its result is what `tspline param` writes; we write it too.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "meshopt/node_smoother.h"                        // meshopt::smooth
#include "tspline/boundary/boundary_map.h"                // BoundaryMap (chord length)
#include "tspline/boundary/boundary_refinement.h"         // refine_to_boundary
#include "tspline/boundary/corners.h"                     // choose_corners
#include "tspline/boundary/polygon_validation.h"          // validate_polygon
#include "tspline/io/param_output.h"                      // param_report, write_param_outputs
#include "tspline/io/polygon_reader.h"                    // read_polygon (text or GeoJSON)
#include "tspline/pipeline/adaptive_parameterization.h"  // run_parameterization
#include "tspline/spline/tspline_fit.h"                   // fit_tspline
#include "tspline/tmesh/coons.h"                          // coons_positions
#include "tspline/tmesh/mesh_quality.h"                   // mesh_quality
#include "tspline/tmesh/smoothing_problem.h"              // build_smoothing_problem
#include "tspline/validity/map_certification.h"           // certify_map
#include "tspline/validity/map_quality.h"                 // map_quality, dense_map_quality
#include "tspline/validity/map_quality_bounds.h"          // certified_map_quality
#include "tspline/validity/map_untangling.h"              // untangle_map

namespace {

std::size_t print_mesh(const char* step, const tspline::TMesh& mesh, const std::vector<Eigen::Vector2d>& x) {
  const tspline::MeshQualityStats q = tspline::mesh_quality(mesh, x);
  std::printf("%s: %zu cells, %zu inverted, min/mean triangle quality %.4f / %.4f\n", step, mesh.num_cells(),
              q.inverted_cells, q.min_mean_ratio, q.mean_mean_ratio);
  return q.inverted_cells;
}

void print_map(const char* step, const tspline::TSplineMap& map) {
  // J_r = 2 det J / |J|_F^2 over the whole map: a dense sample of every Bezier
  // element (not only the Gauss points), and the proof of det J > 0.
  const tspline::DenseMapQuality dense = tspline::dense_map_quality(map);
  const tspline::MapCertification cert = tspline::certify_map(map);
  std::printf("%s: min J_r %.4f (dense sample), %zu of %zu samples with det J <= 0; %zu of %zu elements certified\n",
              step, dense.min_mean_ratio, dense.nonpositive_det, dense.points, cert.certified, cert.elements);
}

}  // namespace

int run(int argc, char** argv) {
  const std::string input = argc > 1 ? argv[1] : TSPLINE_DATA_DIR "/polygons/flower.txt";
  const std::string out = argc > 2 ? argv[2] : "out/ex1";

  // 1. Read the polygon: one "x y" pair per line ('#' starts a comment). The
  //    reader rejects empty files, NaN, ... with an InputError naming the line.
  const tspline::Polygon polygon = tspline::io::read_polygon(input);

  // 2. Validate it (simple, not degenerate; CGAL's exact predicates) and
  //    orient it counter-clockwise.
  const tspline::Polygon ccw = tspline::validate_polygon(polygon);
  std::printf("1-2. polygon: %zu vertices, area %.6g\n", ccw.vertices.size(), tspline::signed_area(ccw));

  // 3. Four corners for the corners of the unit square (Brovka 2013 Sect. 3:
  //    the vertices closest to the corners of the bounding box, refined).
  const tspline::Corners corners = tspline::choose_corners(ccw);

  // 4. The boundary mapped onto the four sides of [0,1]^2 by chord length.
  const tspline::BoundaryMap boundary(ccw, corners);

  // 5. A balanced quadtree T-mesh, level 3, refined at the boundary until every
  //    polygon vertex is within the area tolerance of its cell edge (Sect. 3).
  tspline::TMesh mesh(3);
  Eigen::Vector2d lo = ccw.vertices.front(), hi = lo;  // the bounding box
  for (const Eigen::Vector2d& v : ccw.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  tspline::BoundaryRefinementOptions refinement;
  refinement.tolerance_area = 1e-5 * (hi - lo).squaredNorm();  // the default of `tspline param`
  tspline::refine_to_boundary(mesh, boundary, refinement);

  // 6. Start: the Coons patch of the boundary map, at every T-mesh vertex.
  std::vector<Eigen::Vector2d> x = tspline::coons_positions(mesh, boundary);
  const std::size_t coons_inverted = print_mesh("5-6. Coons start", mesh, x);

  // 7. Untangle and smooth the interior vertices: Gauss-Seidel sweeps of
  //    per-node Newton steps on the weighted K* objective (Sect. 4, libmeshopt).
  const meshopt::SmoothingReport smoothing = meshopt::smooth(x, tspline::build_smoothing_problem(mesh), {});
  std::printf("7. optimization: %d sweeps%s\n", smoothing.sweeps, smoothing.converged ? "" : " (not converged)");
  const std::size_t optimized_inverted = print_mesh("7. optimized", mesh, x);

  // 8. The cubic T-spline interpolating the optimized vertices (Sect. 5,
  //    Eq. 8), its quality, then the global untangling of its control points
  //    (Ceres L-BFGS on a foldover-free energy) and the certificate again.
  tspline::TSplineMap map = tspline::fit_tspline(mesh, x, boundary);
  std::printf("8. T-spline: %zu functions\n", map.basis().size());
  print_map("8. interpolating map", map);
  const tspline::MapUntanglingReport untangling = tspline::untangle_map(map);
  std::printf("8. untangling: %d stages, %d evaluations, %s\n", untangling.stages, untangling.evaluations,
              untangling.stop_reason.c_str());
  print_map("8. untangled map", map);

  // 9. All of the above in one call, plus corner trials, nested optimization,
  //    repair and adaptive refinement (delta of Sect. 6.2: cells whose J_r
  //    falls below it are refined) until det J > 0 is certified on every
  //    Bezier element. Then the files of `tspline param` (atomically).
  tspline::ParameterizationOptions options;
  tspline::AdaptiveOptions adaptive;
  adaptive.min_jacobian = 0.2;
  const tspline::ParameterizationResult result = tspline::run_parameterization(polygon, options, adaptive);
  tspline::io::write_param_outputs(result, out, tspline::io::param_report(result, input), 4);
  print_map("9. run_parameterization", *result.map);

  // The summary, one "key value" per line. J_r: its minimum at the 4x4 Gauss
  // points of every cell (the paper's criterion, >= delta for a good map) and
  // over the whole map (dense sample and Gauss points: never larger).
  std::printf("coons_inverted %zu\noptimized_inverted %zu\n", coons_inverted, optimized_inverted);
  std::printf("cells %zu\nfunctions %zu\nvalid %d\ncertified %d\n", result.map->mesh().num_cells(),
              result.map->basis().size(), result.valid() ? 1 : 0, result.certified_valid() ? 1 : 0);
  std::printf("min_jr_gauss %.6f\nmin_jr_whole_map %.6f\nmean_jr %.6f\n", result.quality.min_mean_ratio,
              result.dense_quality.min_mean_ratio, result.quality.mean_mean_ratio);
  // And a certified lower bound of J_r over the whole map (never above any sample).
  std::printf("min_jr_certified %.6f\n", tspline::certified_map_quality(*result.map).mean_ratio.lower_bound);
  // A valid map has det J > 0 at every Gauss point; "good" also has J_r >= delta.
  return result.good() ? 0 : 1;
}
