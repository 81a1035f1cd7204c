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

#include "tspline/spline/bezier_extraction.h"
#include "bench_front_args.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"
#include "tspline/pipeline/parameterization.h"
#include "tspline/spline/tspline_fit.h"

using bench::since;

int main(int argc, char** argv) {
  const std::optional<tspline::FrontResult> front_result = bench::front_from_args(argc, argv);
  if (!front_result) return 1;
  const tspline::FrontResult& front = *front_result;
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
