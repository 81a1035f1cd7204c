// Benchmark of the T-spline stages on one domain at one resolution: basis
// construction, interpolation (assembly + sparse LU), Jacobian check at 4x4
// Gauss points, and a 20-sweep control point optimization. Prints one row:
//   cells functions basis_s fit_s check_s cpo20_s peak_MiB min_Jr
// Usage: bench_fit POLYGON INIT_LEVEL [TOL_REL]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "tspline/control_point_optimization.h"
#include "tspline/io/polygon_reader.h"
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
  const tspline::TSplineBasis basis(front.mesh);
  const double t_basis = since(t);
  t = std::chrono::steady_clock::now();
  tspline::FitReport rep;
  tspline::TSplineMap map = tspline::fit_tspline(front.mesh, front.optimized, front.boundary, &rep);
  const double t_fit = since(t);  // includes its own basis construction
  t = std::chrono::steady_clock::now();
  const tspline::MapQualityStats q = tspline::map_quality(map, 4);
  const double t_check = since(t);
  t = std::chrono::steady_clock::now();
  tspline::ControlPointOptimizationOptions copt;
  copt.max_sweeps = 20;
  copt.node.newton_iterations_per_visit = 1;
  copt.region_below = 0.4;  // as in tspline param (2 x the default min J_r)
  tspline::optimize_control_points(map, copt);
  const double t_cpo = since(t);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%9zu %9zu %9.4f %9.4f %9.4f %9.4f %9.1f %8.3f\n", front.mesh.num_cells(), basis.size(), t_basis, t_fit,
              t_check, t_cpo, ru.ru_maxrss / 1024.0, q.min_mean_ratio);
  return 0;
}
