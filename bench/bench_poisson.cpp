// Benchmark of the IGA Poisson solver: uniform analysis T-mesh of 2^L x 2^L cells
// on the unit square (geometry = the identity as a cubic T-spline on a 4x4
// T-mesh, control points at the Greville abscissae), u = sin(pi x) sin(pi y).
// Prints one table row:
//   level cells dofs space_s dirichlet_s assembly_s solve_s solver residual max_err peak_MiB
// (space_s: analysis T-mesh + hierarchical B-spline basis; solve_s: factorization + solve;
// max_err: max |u - u_h| at the centres of about 16 x 16 cells, a cheap check
// that the solve is right).
// Usage: bench_poisson LEVEL
// Run one size per process so the peak memory (getrusage) belongs to that size.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <vector>

#include "tspline/poisson.h"

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The identity on [0,1]^2 as a T-spline map on a uniform T-mesh (Greville control points).
tspline::TSplineMap identity_map(int level) {
  tspline::TMesh m(level);
  m.build_topology();
  return tspline::greville_identity_map(std::move(m));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s LEVEL   (analysis mesh of 2^LEVEL x 2^LEVEL cells, LEVEL >= 2)\n",
                 argv[0]);
    return 1;
  }
  const int level = std::atoi(argv[1]);
  if (level < 2 || level > 12) {
    std::fprintf(stderr, "LEVEL must be in [2, 12]\n");
    return 1;
  }
  constexpr double pi = std::numbers::pi;
  tspline::PoissonProblem p;
  p.exact = [](double x, double y) { return std::sin(pi * x) * std::sin(pi * y); };
  p.f = [](double x, double y) { return 2 * pi * pi * std::sin(pi * x) * std::sin(pi * y); };
  p.g = p.exact;
  const tspline::TSplineMap map = identity_map(2);

  auto t0 = Clock::now();
  tspline::TMesh mesh(level);
  mesh.build_topology();
  auto space = std::make_shared<const tspline::AnalysisSpace>(map, std::move(mesh));
  const double space_s = seconds_since(t0);
  const tspline::PoissonSolution sol = tspline::solve_poisson(map, space, p);

  // Cheap correctness check on a 16 x 16 grid of cell centres.
  double max_err = 0.0;
  const tspline::TMesh& m = space->mesh();
  const int n = 1 << level, stride = std::max(1, n / 16);
  for (int j = 0; j < n; j += stride)
    for (int i = 0; i < n; i += stride) {
      const Eigen::Vector2d uv((i + 0.5) / n, (j + 0.5) / n);
      const tspline::SolutionValue v = tspline::evaluate_solution(map, sol, space->basis().locate(uv), uv, 0);
      max_err = std::max(max_err, std::abs(v.u - p.exact(v.x.x(), v.x.y())));
    }

  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%5d %9zu %9zu %8.3f %11.3f %10.3f %8.3f %-6s %9.1e %9.1e %9.1f\n", level, m.num_cells(),
              space->num_dofs(), space_s, sol.dirichlet_seconds, sol.assembly_seconds, sol.solver.seconds,
              sol.solver.kind == "CholmodSupernodalLLT" ? "CHOLMOD" : sol.solver.kind == "SimplicialLDLT" ? "LDLT" : "CG+IC", sol.solver.relative_residual, max_err,
              ru.ru_maxrss / 1024.0);
  return 0;
}
