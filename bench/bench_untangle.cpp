// Benchmark of the global untangling of the T-spline map (map_untangling.h):
// the front half at the given resolution (default options otherwise), the
// interpolating fit, then untangle_map. Prints one row per continuation stage
// (with -v) and a summary row:
//   cells elements free_points samples stages iterations evals seconds certified min_rel_bound min_Jr_samples
// (iterations: Newton or L-BFGS), after a line with the Newton counters, the CPU time
// (user + system, all threads) of the untangling and the peak resident memory.
// Usage: bench_untangle POLYGON [INIT_LEVEL [TOL_REL]] [-v] [--pipeline]
// --pipeline: untangle the map that `tspline param --layout single` untangles
// in its first round (run_parameterization without the control point
// optimization and without adaptive rounds: the fit after the boundary curve
// is frozen, all corner trials), instead of the fit of the front half alone.
// UNTANGLE_OPTIMIZER=newton|lbfgs selects the optimizer (default: the library's, L-BFGS).
// UNTANGLE_THREADS=N: threads of the energy (default: all cores).
// UNTANGLE_NEWTON_SOLVER=cholesky|cg|auto, UNTANGLE_NEWTON_MIN_DECREASE=S,
// UNTANGLE_NEWTON_STALLED_MIN_DECREASE=S: Newton's linear solve and eps rule;
// UNTANGLE_NEWTON_AFTER_STALLED_STAGES=K: L-BFGS hands over to Newton after K stalled stages (0: never).
// UNTANGLE_SOLVE_TEST=EPS: the projected Hessian at the starting map (eps 0.2 |min det J| if folded,
// else EPS) solved by CHOLMOD and by CG with diagonal and incomplete-Cholesky preconditioners
// to relative residuals 1e-1, 1e-2, 1e-4 (time, iterations, distance to the exact step), and exits.
// UNTANGLE_KERNEL_PASSES=N first times N energy-and-gradient passes and N Hessian
// assemblies at the starting map (eps 0.01), CPU time per sample, and exits.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>

#include "bench_front_args.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/validity/map_quality.h"
#include "tspline/validity/map_energy.h"
#include "tspline/validity/map_untangling.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/pipeline/parameterization.h"
#include "tspline/spline/tspline_fit.h"

using bench::since;

namespace {
double cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}
}  // namespace

int main(int argc, char** argv) {
  bool verbose = false;
  bool pipeline = false;
  int n = 0;
  char* args[4] = {nullptr, nullptr, nullptr, nullptr};
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-v") == 0)
      verbose = true;
    else if (std::strcmp(argv[i], "--pipeline") == 0)
      pipeline = true;
    else if (n < 3)
      args[n++] = argv[i];
  }
  if (n < 1) {
    std::fprintf(stderr, "usage: %s POLYGON [INIT_LEVEL [TOL_REL]] [-v] [--pipeline]\n", argv[0]);
    return 1;
  }
  tspline::ParameterizationOptions opt;
  if (n > 1) {
    opt.initial_level = std::atoi(args[1]);
    // Level 9 is 2^18 = 262,144 cells before any boundary refinement: room for 4x that.
    if (opt.initial_level >= 0 && opt.initial_level <= 12)
      opt.max_cells = std::max(opt.max_cells, std::size_t{4} << (2 * opt.initial_level));
  }
  if (n > 2) opt.tolerance_relative = std::atof(args[2]);
  auto t = std::chrono::steady_clock::now();
  std::optional<tspline::TSplineMap> input;
  std::optional<tspline::FrontResult> front_result;
  if (pipeline) {
    tspline::AdaptiveOptions ad;
    ad.optimize_control_points = false;
    ad.max_adapt = 0;
    tspline::ParameterizationResult pr = tspline::run_parameterization(tspline::io::read_polygon(args[0]), opt, ad);
    input = std::move(*pr.map);
    front_result = std::move(pr.front);
  } else {
    front_result = tspline::run_front(tspline::io::read_polygon(args[0]), opt);
    input = tspline::fit_tspline(front_result->mesh, front_result->optimized, front_result->boundary);
  }
  const tspline::FrontResult& front = *front_result;
  const double t_front = since(t);
  tspline::TSplineMap map = std::move(*input);
  tspline::MapUntanglingOptions uopt;
  // Experiment knobs (environment): iterations per stage, element weighting.
  if (const char* v = std::getenv("UNTANGLE_STAGE_ITERATIONS")) uopt.max_iterations_per_stage = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_AREA_WEIGHTS"); v && *v == '1')
    uopt.energy.weighting = tspline::ElementWeighting::Area;
  if (const char* v = std::getenv("UNTANGLE_MIN_DECREASE")) uopt.min_decrease = std::atof(v);
  if (const char* v = std::getenv("UNTANGLE_GAUSS")) uopt.energy.gauss = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_LEGENDRE"); v && *v == '1') uopt.energy.lobatto = false;
  if (const char* v = std::getenv("UNTANGLE_NEWTON_SOLVER"))
    uopt.newton_solver = std::strcmp(v, "cg") == 0         ? tspline::NewtonSolver::ConjugateGradient
                         : std::strcmp(v, "cholesky") == 0 ? tspline::NewtonSolver::Cholesky
                                                           : tspline::NewtonSolver::Auto;
  if (const char* v = std::getenv("UNTANGLE_NEWTON_MIN_DECREASE")) uopt.newton_min_decrease = std::atof(v);
  if (const char* v = std::getenv("UNTANGLE_NEWTON_AFTER_STALLED_STAGES")) uopt.newton_after_stalled_stages = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_NEWTON_STALLED_MIN_DECREASE"))
    uopt.newton_stalled_min_decrease = std::atof(v);
  if (const char* v = std::getenv("UNTANGLE_THREADS")) uopt.energy.threads = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_OPTIMIZER"))
    uopt.optimizer = std::strcmp(v, "newton") == 0  ? tspline::MapOptimizer::Newton
                     : std::strcmp(v, "ceres") == 0 ? tspline::MapOptimizer::CeresLBFGS
                                                    : tspline::MapOptimizer::LBFGS;
  if (const char* v = std::getenv("UNTANGLE_NEWTON_ITERATIONS")) uopt.max_newton_iterations_per_stage = std::atoi(v);
  if (const char* v = std::getenv("UNTANGLE_NEWTON_TOL")) uopt.newton_stage_tolerance = std::atof(v);
  if (verbose)
    uopt.progress = [](const tspline::UntanglingProgress& p) {
      std::printf("  stage %3d eps %9.3g E %12.6g iters %6d samples det<=0 %7zu min det %10.3g min Jr %8.4f%s\n",
                  p.stage, p.eps, p.energy, p.iterations, p.samples.nonpositive, p.samples.min_det,
                  p.samples.min_mean_ratio, p.certified ? " certified" : "");
      std::fflush(stdout);
    };
  if (const char* v = std::getenv("UNTANGLE_KERNEL_PASSES")) {
    const int passes = std::max(1, std::atoi(v));
    const tspline::MapEnergy energy(map, uopt.energy);
    const Eigen::VectorXd x = energy.variables(map);
    Eigen::VectorXd g(x.size());
    double sum = 0.0;
    double c = cpu_seconds();
    auto w = std::chrono::steady_clock::now();
    for (int i = 0; i < passes; ++i) sum += energy.evaluate(x.data(), 0.01, g.data());
    const double cpu_eval = (cpu_seconds() - c) / passes, wall_eval = since(w) / passes;
    Eigen::SparseMatrix<double> H;
    energy.hessian(x.data(), 0.01, H);  // the pattern, once
    c = cpu_seconds();
    w = std::chrono::steady_clock::now();
    for (int i = 0; i < passes; ++i) energy.hessian(x.data(), 0.01, H);
    const double cpu_hess = (cpu_seconds() - c) / passes, wall_hess = since(w) / passes;
    const double ns = 1e9 / static_cast<double>(energy.num_samples());
    std::printf("%zu samples, %zu unknowns, H nnz (lower) %ld: energy+gradient %.2f ms CPU (%.1f ns/sample), %.2f ms wall; "
                "Hessian %.2f ms CPU (%.1f ns/sample), %.2f ms wall  [E %.6g]\n",
                energy.num_samples(), energy.num_variables(), static_cast<long>(H.nonZeros()), 1e3 * cpu_eval,
                cpu_eval * ns, 1e3 * wall_eval, 1e3 * cpu_hess, cpu_hess * ns, 1e3 * wall_hess, sum / passes);
    return 0;
  }
  if (const char* v = std::getenv("UNTANGLE_SOLVE_TEST")) {
    const tspline::MapEnergy energy(map, uopt.energy);
    const Eigen::VectorXd x = energy.variables(map);
    const tspline::SampleStats st = energy.stats(x.data());
    const double eps = st.nonpositive > 0 ? std::clamp(0.2 * std::abs(st.min_det), 1e-3, 1.0) : std::atof(v);
    Eigen::VectorXd g(x.size());
    energy.evaluate(x.data(), eps, g.data());
    Eigen::SparseMatrix<double> H;
    energy.hessian(x.data(), eps, H);
    double c = cpu_seconds();
    energy.hessian(x.data(), eps, H);
    std::printf("n %ld nnz(lower) %ld, eps %g, hessian %.1f ms\n", (long)H.rows(), (long)H.nonZeros(), eps, 1e3 * (cpu_seconds() - c));
    {
      Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
      c = cpu_seconds();
      llt.analyzePattern(H);
      const double ta = cpu_seconds() - c;
      c = cpu_seconds();
      llt.factorize(H);
      const double tf = cpu_seconds() - c;
      Eigen::VectorXd d = llt.solve(-g);
      std::printf("cholmod supernodal: analyze %.1f ms factorize %.1f ms, info %d, |d| %g\n", 1e3 * ta, 1e3 * tf, (int)llt.info(), d.norm());
      Eigen::SparseMatrix<double> Hf = H.selfadjointView<Eigen::Lower>();
      for (int pre = 0; pre < 2; ++pre)
        for (double tol : {1e-1, 1e-2, 1e-4}) {
          c = cpu_seconds();
          Eigen::VectorXd y;
          int its = 0;
          double err = 0;
          // CG with the preconditioner of type Pre (a std::type_identity<Pre>).
          auto solve_cg = [&](auto preconditioner) {
            using Pre = typename decltype(preconditioner)::type;
            Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, Pre> cg;
            cg.setTolerance(tol);
            cg.setMaxIterations(5000);
            cg.compute(Hf);
            y = cg.solve(-g);
            its = cg.iterations(), err = cg.error();
          };
          if (pre == 0)
            solve_cg(std::type_identity<Eigen::DiagonalPreconditioner<double>>{});
          else
            solve_cg(std::type_identity<Eigen::IncompleteCholesky<double>>{});
          std::printf("  CG %s tol %g: %d its, err %g, %.1f ms, |y - d|/|d| %.3g, slope ratio %.3f\n", pre ? "IC" : "Jacobi", tol, its, err, 1e3 * (cpu_seconds() - c), (y - d).norm() / d.norm(), g.dot(y) / g.dot(d));
        }
    }
    return 0;
  }
  t = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  const tspline::MapUntanglingReport r = tspline::untangle_map(map, uopt);
  const double t_untangle = since(t);
  const double cpu_untangle = cpu_seconds() - cpu0;
  std::printf("front %.2f s; before: %zu of %zu samples det<=0, min Jr %.4f; local repairs %d (%d certified), %d iterations, %.2f s\n",
              t_front, r.before.nonpositive, r.before.points, r.before.min_mean_ratio, r.local_repairs,
              r.local_repairs_certified, r.local_repair_iterations, r.local_repair_seconds);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  if (r.newton_from_stage >= 0) std::printf("L-BFGS stalled: Newton from stage %d\n", r.newton_from_stage);
  std::printf("%s: hessians %d (%.2f s), shifted %d, solves %.2f s (CG iterations %d), certified trial steps %d; CPU %.2f s; peak RSS %.0f MiB; mean Jr %.4f\n",
              uopt.optimizer == tspline::MapOptimizer::Newton ? "newton"
              : uopt.optimizer == tspline::MapOptimizer::CeresLBFGS ? "ceres"
                                                                    : "lbfgs",
              r.factorizations,
              r.hessian_seconds, r.shifted_factorizations, r.solve_seconds, r.cg_iterations, r.line_search_certifications, cpu_untangle, ru.ru_maxrss / 1024.0,
              r.after.mean_mean_ratio);
  std::printf("%9zu %9zu %9zu %9zu %6d %7d %7d %9.3f %9s %13.4g %9.4f  (%s)\n", front.mesh.num_cells(), r.elements,
              r.free_points, r.samples, r.stages, r.iterations, r.evaluations, t_untangle,
              r.certified ? "yes" : "no", r.certification.min_relative_lower_bound, r.after.min_mean_ratio,
              r.stop_reason.c_str());
  if (std::getenv("UNTANGLE_POLISH") && r.certified) {
    // The pipeline's polish (AdaptiveOptions::polish_*): 12 more quality stages at power 8.
    tspline::MapUntanglingOptions po = uopt;
    po.max_quality_stages = 12;
    po.quality_power = 8.0;
    po.progress = nullptr;
    tspline::TSplineMap polished = map;
    const double c = cpu_seconds();
    const tspline::MapUntanglingReport p = tspline::untangle_map(polished, po);
    const tspline::DenseMapQuality d0 = tspline::dense_map_quality(map, 25), d1 = tspline::dense_map_quality(polished, 25);
    std::printf("polish: %d stages, %d iterations, %.2f s CPU, certified %d; min Jr samples %.4f -> %.4f, dense 26x26 %.4f -> %.4f\n",
                p.stages, p.iterations, cpu_seconds() - c, (int)p.certified, r.after.min_mean_ratio, p.after.min_mean_ratio,
                d0.min_mean_ratio, d1.min_mean_ratio);
  }
  return r.certified ? 0 : 3;
}
