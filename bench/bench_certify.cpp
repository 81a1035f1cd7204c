// Benchmark of the certified validity check (map_certification.h) against the
// rest of the T-spline stages on one domain at one resolution: the fitted map of
// the front half's T-mesh, then Bezier extraction alone, the full certification
// (extraction + Bernstein numerator + subdivision) and the 4x4 Gauss check.
// Prints one row:
//   cells elements functions fit_s extract_s certify_s us_per_element check_s certified min_rel_bound max_depth
// Usage: bench_certify POLYGON INIT_LEVEL [TOL_REL]
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "tspline/bezier_extraction.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/map_certification.h"
#include "tspline/map_quality.h"
#include "tspline/parameterization.h"
#include "tspline/tspline_fit.h"

namespace {
double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s POLYGON INIT_LEVEL [TOL_REL]\n", argv[0]);
    return 1;
  }
  tspline::ParameterizationOptions opt;
  opt.initial_level = std::atoi(argv[2]);
  opt.tolerance_relative = argc > 3 ? std::atof(argv[3]) : 1e-6;
  opt.corner_trials = 1;
  const tspline::FrontResult front = tspline::run_front(tspline::io::read_polygon(argv[1]), opt);
  auto t = std::chrono::steady_clock::now();
  const tspline::TSplineMap map = tspline::fit_tspline(front.mesh, front.optimized, front.boundary);
  const double t_fit = since(t);
  t = std::chrono::steady_clock::now();
  const tspline::BezierExtraction extraction(map.basis());
  const double t_extract = since(t);
  t = std::chrono::steady_clock::now();
  const tspline::MapCertification c = tspline::certify_map(map);
  const double t_certify = since(t);
  t = std::chrono::steady_clock::now();
  tspline::map_quality(map, 4);
  const double t_check = since(t);
  std::printf("%9zu %9zu %9zu %9.4f %9.4f %9.4f %9.2f %9.4f %9s %13.4g %9d\n", front.mesh.num_cells(), c.elements,
              map.basis().size(), t_fit, t_extract, t_certify, 1e6 * t_certify / static_cast<double>(c.elements),
              t_check, c.certified_valid() ? "yes" : "no", c.min_relative_lower_bound, c.max_depth_used);
  return extraction.elements().size() == c.elements ? 0 : 1;
}
