// Benchmark of the certified whole-map quality bounds (map_quality_bounds.h)
// on the map of a T-spline file (format 1 or 2, every patch): the bounds as
// the report computes them (the dense sample only where it can hold the
// minimum), with the sample of every element (per_element), and without the
// sample; seconds (one thread), elements sampled, subdivision patches per
// element, the bounds and the sampled minima.
// Usage: bench_quality_bounds TSPLINE_JSON
#include <chrono>
#include <cstdio>
#include <exception>

#include "tspline/io/multipatch_file.h"
#include "tspline/io/param_output.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/validity/map_quality_bounds.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: bench_quality_bounds TSPLINE_JSON\n");
    return 1;
  }
  try {
    const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(argv[1]);
    std::vector<const tspline::TSplineMap*> ptrs;
    for (const auto& p : maps.patches) ptrs.push_back(&p.map);
    {
      // The Bezier extraction of every patch (which the bounds, the certificate
      // and the output files start from), with a checksum of its coefficients.
      const auto t0 = std::chrono::steady_clock::now();
      std::size_t elements = 0;
      double checksum = 0.0;
      for (const tspline::TSplineMap* m : ptrs) {
        const tspline::BezierExtraction x(m->basis());
        elements += x.elements().size();
        for (const tspline::BezierElement& e : x.elements()) checksum += e.C.sum();
      }
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("Bezier extraction: %zu elements: %.3f s (%.2f us per element), coefficient sum %.17g\n",
                  elements, s, 1e6 * s / static_cast<double>(elements), checksum);
    }
    struct Mode {
      const char* name;
      int samples;
      bool every;
    };
    for (const Mode m :
         {Mode{"report", 25, false}, Mode{"every element sampled", 25, true}, Mode{"no sample", 0, false}}) {
      tspline::QualityBoundOptions o = tspline::io::report_quality_bound_options();
      o.samples_per_edge = m.samples;
      o.per_element = m.every;
      o.threads = 1;
      const auto t0 = std::chrono::steady_clock::now();
      const tspline::MapQualityBounds b = tspline::certified_map_quality(ptrs, o);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf(
          "%s: %zu patches, %zu elements, %zu sampled (%d per edge): %.3f s (%.1f us per element), %.2f "
          "subdivision patches per element, depth %d, %zu not converged; J_r >= %.4g (attained %.4g, sampled "
          "%.4g), SJ >= %.4g (attained %.4g, sampled %.4g)\n",
          m.name, ptrs.size(), b.elements, b.sampled_elements, m.samples, s,
          1e6 * s / static_cast<double>(b.elements),
          static_cast<double>(b.patches) / static_cast<double>(b.elements), b.max_depth_used,
          b.elements_not_converged, b.mean_ratio.lower_bound, b.mean_ratio.attained, b.mean_ratio.sampled,
          b.scaled.lower_bound, b.scaled.attained, b.scaled.sampled);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_quality_bounds: %s\n", e.what());
    return 1;
  }
  return 0;
}
