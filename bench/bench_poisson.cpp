// Benchmark of the IGA Poisson solver: uniform analysis T-mesh of 2^L x 2^L cells
// on the unit square (geometry = the identity as a cubic T-spline on a 4x4
// T-mesh, control points at the Greville abscissae), u = sin(pi x) sin(pi y).
// Prints one table row:
//   level cells dofs space_s dirichlet_s assembly_s solve_s solver residual max_err peak_MiB
//   ranks its peak_total_MiB assembly_cpu_s solve_cpu_s
// (peak_MiB: the largest peak of one process; peak_total_MiB: their sum.)
// (space_s: analysis T-mesh + hierarchical B-spline basis; solve_s: factorization + solve;
// max_err: max |u - u_h| at the centres of about 16 x 16 cells, a cheap check
// that the solve is right; *_cpu_s: CPU time of rank 0's process (std::clock)
// for the iterative solver's assembly and solve, which a loaded machine
// inflates less than the wall times; -1 for the direct solver).
// Usage: [mpirun -n P] bench_poisson LEVEL [direct|iterative] [boomeramg|gamg] [RTOL]
// (default direct; the iterative solver is PETSc CG + AMG, tspline/petsc_solver.h,
// with the default (automatic) rtol of `tspline poisson` unless RTOL is given.)
// Run one size per process so the peak memory (getrusage) belongs to that size.
#include <petscsys.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <numbers>
#include <numeric>
#include <vector>

#include <string>

#include "tspline/petsc_solver.h"
#include "tspline/analysis/poisson.h"

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

/// The PETSc solver, with the CPU time of its assembly (begin .. end_assembly)
/// and solve measured around it.
class TimedSolver final : public tspline::InteriorSystemSolver {
 public:
  explicit TimedSolver(tspline::InteriorSystemSolver& inner) : inner_(inner) {}
  bool accepts(std::size_t ni) const override { return inner_.accepts(ni); }
  std::vector<int> begin(const tspline::AnalysisSpace& space, const std::vector<int>& interior, int ni) override {
    c0_ = std::clock();
    return inner_.begin(space, interior, ni);
  }
  void add_cell(std::span<const int> rows, const Eigen::MatrixXd& Kloc, const Eigen::VectorXd& floc) override {
    inner_.add_cell(rows, Kloc, floc);
  }
  bool end_assembly(bool ok) override {
    const bool r = inner_.end_assembly(ok);
    assembly_cpu = cpu_since(c0_);
    return r;
  }
  tspline::SolverStats solve(Eigen::VectorXd& u) override {
    const std::clock_t c = std::clock();
    tspline::SolverStats st = inner_.solve(u);
    solve_cpu = cpu_since(c);
    return st;
  }
  double assembly_cpu = -1, solve_cpu = -1;

 private:
  static double cpu_since(std::clock_t c) { return static_cast<double>(std::clock() - c) / CLOCKS_PER_SEC; }
  tspline::InteriorSystemSolver& inner_;
  std::clock_t c0_ = 0;
};

int run(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: %s LEVEL [direct|iterative] [boomeramg|gamg] [RTOL]  (analysis mesh of 2^LEVEL x 2^LEVEL "
                 "cells, LEVEL >= 2)\n",
                 argv[0]);
    return 1;
  }
  const int level = std::atoi(argv[1]);
  if (level < 2 || level > 12) {
    std::fprintf(stderr, "LEVEL must be in [2, 12]\n");
    return 1;
  }
  tspline::petsc::IterativeOptions io;
  io.choice = tspline::petsc::parse_solver_choice(argc > 2 ? argv[2] : "direct");
  if (io.choice == tspline::petsc::SolverChoice::Auto) io.choice = tspline::petsc::SolverChoice::Direct;
  if (argc > 3) io.preconditioner = tspline::petsc::parse_preconditioner(argv[3]);
  if (argc > 4) io.rtol = std::atof(argv[4]);
  tspline::petsc::PetscPoissonSolver petsc_solver(io);
  TimedSolver solver(petsc_solver);
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
  const tspline::PoissonSolution sol = tspline::solve_poisson(space, p, &solver);

  // Cheap correctness check on a 16 x 16 grid of cell centres.
  double max_err = 0.0;
  const tspline::TMesh& m = space->patch(0).mesh();
  const int n = 1 << level, stride = std::max(1, n / 16);
  for (int j = 0; j < n; j += stride)
    for (int i = 0; i < n; i += stride) {
      const Eigen::Vector2d uv((i + 0.5) / n, (j + 0.5) / n);
      const tspline::SolutionValue v = tspline::evaluate_solution(sol, 0, uv);
      max_err = std::max(max_err, std::abs(v.u - p.exact(v.x.x(), v.x.y())));
    }

  const std::vector<double> peak = tspline::petsc::peak_memory_mib();
  if (tspline::petsc::process_rank() != 0) return 0;
  const std::string& k = sol.solver.kind;
  const char* name = k == "CholmodSupernodalLLT"         ? "CHOLMOD"
                     : k == "SimplicialLDLT"             ? "LDLT"
                     : k == "PETSc CG + hypre BoomerAMG" ? "BoomerAMG"
                     : k == "PETSc CG + PETSc GAMG"      ? "GAMG"
                                                         : "CG+IC";
  std::printf("%5d %9zu %9zu %8.3f %11.3f %10.3f %8.3f %-9s %9.1e %9.1e %9.1f %5d %5d %9.1f %8.3f %8.3f\n", level,
              m.num_cells(), space->num_dofs(), space_s, sol.dirichlet_seconds, sol.assembly_seconds,
              sol.solver.seconds, name, sol.solver.relative_residual, max_err,
              *std::max_element(peak.begin(), peak.end()), tspline::petsc::process_count(), sol.solver.iterations,
              std::accumulate(peak.begin(), peak.end(), 0.0), solver.assembly_cpu, solver.solve_cpu);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (PetscInitializeNoArguments() != 0) return 1;
  int rc = 1;
  try {
    rc = run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_poisson: %s\n", e.what());
  }
  PetscFinalize();
  return rc;
}
