// Benchmark of the certified validity check (map_certification.h) against the
// rest of the T-spline stages on one domain at one resolution: the fitted map of
// the front half's T-mesh, then Bezier extraction alone, the full certification
// (extraction + Bernstein numerator + subdivision) and the 4x4 Gauss check.
// Prints one row:
//   cells elements functions fit_s extract_s certify_s us_per_element check_s certified min_rel_bound max_depth
// then one line per run of the certified quality bounds (map_quality_bounds.h:
// lower bounds of J_r and the scaled Jacobian over the whole map) with 1 and 2
// threads, without and with the 26 x 26 sample (as the report takes it: only
// on the elements that can hold the sampled minimum, their number printed):
// seconds, seconds per 10^4 elements, subdivision patches and depth, the bounds.
// Usage: bench_certify POLYGON INIT_LEVEL [TOL_REL]
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "tspline/spline/bezier_extraction.h"
#include "bench_front_args.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"
#include "tspline/validity/map_quality_bounds.h"
#include "tspline/pipeline/parameterization.h"
#include "tspline/spline/tspline_fit.h"

int main(int argc, char** argv) {
  const std::optional<tspline::FrontResult> front_result = bench::front_from_args(argc, argv);
  if (!front_result) return 1;
  const tspline::FrontResult& front = *front_result;
  bench::Laps lap;
  const tspline::TSplineMap map = tspline::fit_tspline(front.mesh, front.optimized, front.boundary);
  const double t_fit = lap();
  const tspline::BezierExtraction extraction(map.basis());
  const double t_extract = lap();
  const tspline::MapCertification c = tspline::certify_map(map);
  const double t_certify = lap();
  tspline::map_quality(map, 4);
  const double t_check = lap();
  std::printf("%9zu %9zu %9zu %9.4f %9.4f %9.4f %9.2f %9.4f %9s %13.4g %9d\n", front.mesh.num_cells(), c.elements,
              map.basis().size(), t_fit, t_extract, t_certify, 1e6 * t_certify / static_cast<double>(c.elements),
              t_check, c.certified_valid() ? "yes" : "no", c.min_relative_lower_bound, c.max_depth_used);
  for (const int threads : {1, 2})
    for (const int samples : {0, 25}) {
      tspline::QualityBoundOptions opt;
      opt.threads = threads;
      opt.samples_per_edge = samples;
      const tspline::MapQualityBounds q = tspline::certified_map_quality(extraction, map.control_points(), opt);
      std::printf("quality bounds: %d thread(s), %2d samples per edge: %.4f s = %.4f s per 10^4 elements; %zu patches, "
                  "depth %d; J_r >= %.5g, SJ >= %.5g",
                  threads, samples, q.seconds, q.seconds * 1e4 / static_cast<double>(q.elements), q.patches,
                  q.max_depth_used, q.mean_ratio.lower_bound, q.scaled.lower_bound);
      if (samples > 0)
        std::printf(" (sampled minima %.5g, %.5g; %zu elements sampled)", q.mean_ratio.sampled, q.scaled.sampled,
                    q.sampled_elements);
      std::printf("\n");
    }
  return extraction.elements().size() == c.elements ? 0 : 1;
}
