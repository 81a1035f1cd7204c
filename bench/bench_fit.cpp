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
#include "bench_front_args.h"
#include "tspline/map_quality.h"
#include "tspline/parameterization.h"
#include "tspline/tspline_fit.h"

using bench::since;

int main(int argc, char** argv) {
  const std::optional<tspline::FrontResult> front_result = bench::front_from_args(argc, argv);
  if (!front_result) return 1;
  const tspline::FrontResult& front = *front_result;
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
