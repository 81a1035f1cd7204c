// Benchmark of the T-spline stages on one domain at one resolution: basis
// construction, interpolation (assembly + sparse LU), Jacobian check at 4x4
// Gauss points, and the dense whole-map sample (81 points per Bezier element).
// Prints one row:
//   cells functions basis_s fit_s check_s dense_s peak_MiB min_Jr
// Usage: bench_fit POLYGON INIT_LEVEL [TOL_REL]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "bench_front_args.h"
#include "tspline/validity/map_quality.h"
#include "tspline/pipeline/parameterization.h"
#include "tspline/spline/tspline_fit.h"

int main(int argc, char** argv) {
  const std::optional<tspline::FrontResult> front_result = bench::front_from_args(argc, argv);
  if (!front_result) return 1;
  const tspline::FrontResult& front = *front_result;
  bench::Laps lap;
  const tspline::TSplineBasis basis(front.mesh);
  const double t_basis = lap();
  tspline::FitReport rep;
  const tspline::TSplineMap map = tspline::fit_tspline(front.mesh, front.optimized, front.boundary, &rep);
  const double t_fit = lap();  // includes its own basis construction
  const tspline::MapQualityStats q = tspline::map_quality(map, 4);
  const double t_check = lap();
  tspline::dense_map_quality(map);
  const double t_dense = lap();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%9zu %9zu %9.4f %9.4f %9.4f %9.4f %9.1f %8.3f\n", front.mesh.num_cells(), basis.size(), t_basis, t_fit,
              t_check, t_dense, ru.ru_maxrss / 1024.0, q.min_mean_ratio);
  return 0;
}
