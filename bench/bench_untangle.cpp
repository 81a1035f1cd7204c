// Benchmark of the global untangling of the T-spline map (map_untangling.h):
// the front half at the given resolution (default options otherwise), the
// interpolating fit, then untangle_map. Prints one row per continuation stage
// (with -v) and a summary row:
//   cells elements free_points samples stages iterations evals seconds certified min_rel_bound min_Jr_samples
// (iterations: Newton or L-BFGS), after a line with the Newton counters and the peak resident memory.
// Usage: bench_untangle POLYGON [INIT_LEVEL [TOL_REL]] [-v]
// UNTANGLE_OPTIMIZER=newton|lbfgs selects the optimizer (default: the library's, L-BFGS).
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "bench_front_args.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/validity/map_untangling.h"
#include "tspline/pipeline/parameterization.h"
#include "tspline/spline/tspline_fit.h"

using bench::since;

int main(int argc, char** argv) {
  bool verbose = false;
  int n = 0;
  char* args[4] = {nullptr, nullptr, nullptr, nullptr};
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-v") == 0)
      verbose = true;
    else if (n < 3)
      args[n++] = argv[i];
  }
  if (n < 1) {
    std::fprintf(stderr, "usage: %s POLYGON [INIT_LEVEL [TOL_REL]] [-v]\n", argv[0]);
    return 1;
  }
  tspline::ParameterizationOptions opt;
  if (n > 1) opt.initial_level = std::atoi(args[1]);
  if (n > 2) opt.tolerance_relative = std::atof(args[2]);
  auto t = std::chrono::steady_clock::now();
  const tspline::FrontResult front = tspline::run_front(tspline::io::read_polygon(args[0]), opt);
  const double t_front = since(t);
  tspline::TSplineMap map = tspline::fit_tspline(front.mesh, front.optimized, front.boundary);
  tspline::MapUntanglingOptions uopt;
  // Experiment knobs (environment): iterations per stage, element weighting.
  if (const char* v = std::getenv("UNTANGLE_STAGE_ITERATIONS")) uopt.max_iterations_per_stage = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_AREA_WEIGHTS"); v && *v == '1')
    uopt.energy.weighting = tspline::ElementWeighting::Area;
  if (const char* v = std::getenv("UNTANGLE_MIN_DECREASE")) uopt.min_decrease = std::atof(v);
  if (const char* v = std::getenv("UNTANGLE_GAUSS")) uopt.energy.gauss = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_LEGENDRE"); v && *v == '1') uopt.energy.lobatto = false;
  if (const char* v = std::getenv("UNTANGLE_OPTIMIZER"))
    uopt.optimizer = std::strcmp(v, "newton") == 0 ? tspline::MapOptimizer::Newton : tspline::MapOptimizer::LBFGS;
  if (const char* v = std::getenv("UNTANGLE_NEWTON_ITERATIONS")) uopt.max_newton_iterations_per_stage = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_NEWTON_TOL")) uopt.newton_stage_tolerance = std::atof(v);
  if (verbose)
    uopt.progress = [](const tspline::UntanglingProgress& p) {
      std::printf("  stage %3d eps %9.3g E %12.6g iters %6d samples det<=0 %7zu min det %10.3g min Jr %8.4f%s\n",
                  p.stage, p.eps, p.energy, p.iterations, p.samples.nonpositive, p.samples.min_det,
                  p.samples.min_mean_ratio, p.certified ? " certified" : "");
      std::fflush(stdout);
    };
  t = std::chrono::steady_clock::now();
  const tspline::MapUntanglingReport r = tspline::untangle_map(map, uopt);
  const double t_untangle = since(t);
  std::printf("front %.2f s; before: %zu of %zu samples det<=0, min Jr %.4f\n", t_front, r.before.nonpositive,
              r.before.points, r.before.min_mean_ratio);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%s: hessians %d (%.2f s), shifted %d, CHOLMOD %.2f s, certified trial steps %d; peak RSS %.0f MiB; mean Jr %.4f\n",
              uopt.optimizer == tspline::MapOptimizer::Newton ? "newton" : "lbfgs", r.factorizations,
              r.hessian_seconds, r.shifted_factorizations, r.solve_seconds, r.line_search_certifications, ru.ru_maxrss / 1024.0,
              r.after.mean_mean_ratio);
  std::printf("%9zu %9zu %9zu %9zu %6d %7d %7d %9.3f %9s %13.4g %9.4f  (%s)\n", front.mesh.num_cells(), r.elements,
              r.free_points, r.samples, r.stages, r.iterations, r.evaluations, t_untangle,
              r.certified ? "yes" : "no", r.certification.min_relative_lower_bound, r.after.min_mean_ratio,
              r.stop_reason.c_str());
  return r.certified ? 0 : 3;
}
