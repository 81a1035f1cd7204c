// Benchmark of the IGA Poisson solver: uniform analysis T-mesh of 2^L x 2^L cells
// on the unit square (geometry = the identity as a cubic T-spline on a 4x4
// T-mesh, control points at the Greville abscissae), u = sin(pi x) sin(pi y);
// or a T-spline file of any number of patches (tspline.json of `tspline
// param`), its first analysis meshes refined uniformly R times, u = the
// built-in sinsin scaled to the domain (manufactured_problems.h).
// Prints one table row:
//   level cells dofs space_s dirichlet_s assembly_s solve_s solver residual max_err peak_MiB
//   ranks its peak_total_MiB assembly_cpu_s solve_cpu_s
// (peak_MiB: the largest peak of one process; peak_total_MiB: their sum.)
// (space_s: analysis T-mesh + hierarchical B-spline basis; solve_s: factorization + solve;
// max_err: max |u - u_h| at the centres of about 16 x 16 cells, a cheap check
// that the solve is right; *_cpu_s: CPU time of rank 0's process (std::clock)
// for the iterative solver's assembly and solve, which a loaded machine
// inflates less than the wall times; -1 for the direct solver).
// Usage: [mpirun -n P] bench_poisson LEVEL|MAP.json R [direct|iterative] [boomeramg|gamg] [RTOL]
// (the first column is then R, `cells` and `dofs` those of every patch)
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
#include "tspline/io/multipatch_file.h"
#include "toolkit/timing.h"

namespace {

using Clock = std::chrono::steady_clock;
using toolkit::seconds_since;

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
  int rank() const override { return inner_.rank(); }
  int processes() const override { return inner_.processes(); }
  std::vector<double> gather_to_all(std::span<const double> v) const override { return inner_.gather_to_all(v); }
  void sum_over_processes(std::span<double> v) const override { inner_.sum_over_processes(v); }
  void max_over_processes(std::span<double> v) const override { inner_.max_over_processes(v); }
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
  const bool on_map = argc > 2 && std::string(argv[1]).ends_with(".json");
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: %s LEVEL|MAP.json R [direct|iterative] [boomeramg|gamg] [RTOL]  (analysis mesh of 2^LEVEL x "
                 "2^LEVEL cells, LEVEL >= 2; or the map's first analysis meshes refined R times)\n",
                 argv[0]);
    return 1;
  }
  const int level = std::atoi(argv[on_map ? 2 : 1]);
  if (on_map ? (level < 0 || level > 10) : (level < 2 || level > 12)) {
    std::fprintf(stderr, on_map ? "R must be in [0, 10]\n" : "LEVEL must be in [2, 12]\n");
    return 1;
  }
  const int a = on_map ? 3 : 2;  // the solver's arguments
  tspline::petsc::IterativeOptions io;
  io.choice = tspline::petsc::parse_solver_choice(argc > a ? argv[a] : "direct");
  if (io.choice == tspline::petsc::SolverChoice::Auto) io.choice = tspline::petsc::SolverChoice::Direct;
  if (argc > a + 1) io.preconditioner = tspline::petsc::parse_preconditioner(argv[a + 1]);
  if (argc > a + 2) io.rtol = std::atof(argv[a + 2]);
  tspline::petsc::PetscPoissonSolver petsc_solver(io);
  TimedSolver solver(petsc_solver);

  const tspline::TSplineMap square = identity_map(2);
  tspline::io::LoadedMaps file;
  tspline::AnalysisGeometry geometry(square);
  if (on_map) {
    file = tspline::io::read_maps_file(argv[1]);
    geometry = {};
    for (const auto& t : file.patches) geometry.patches.push_back(&t.map);
    geometry.interfaces = file.interfaces;
  }
  const tspline::PoissonProblem p = tspline::manufactured_problem("sinsin", geometry).problem;

  auto t0 = Clock::now();
  std::vector<tspline::TMesh> meshes;
  if (on_map) {
    meshes = geometry.meshes();
    for (int k = 0; k < level; ++k) {
      std::vector<std::vector<int>> all(meshes.size());
      for (std::size_t q = 0; q < meshes.size(); ++q) {
        all[q].resize(meshes[q].num_cells());
        for (int c = 0; c < static_cast<int>(all[q].size()); ++c) all[q][c] = c;
      }
      tspline::refine_conforming(meshes, geometry.interfaces, all);
    }
  } else {
    meshes.emplace_back(level);
    meshes.back().build_topology();
  }
  auto space = std::make_shared<const tspline::AnalysisSpace>(geometry, std::move(meshes), solver.rank(),
                                                              solver.processes());
  const double space_s = seconds_since(t0);
  const tspline::PoissonSolution sol = tspline::solve_poisson(space, p, &solver);

  // Cheap correctness check at the centres of about 256 cells of this process's block.
  double max_err = 0.0;
  const auto [first, last] = space->block(solver.rank());
  for (std::size_t gc = first; gc < last; gc += std::max<std::size_t>(1, (last - first) / 256)) {
    const auto [q, c] = space->cell(gc);
    const tspline::TMesh& m = space->mesh(q);
    const tspline::SolutionValue v = tspline::evaluate_solution(sol, q, c, 0.5 * (m.cell_min(c) + m.cell_max(c)), 0);
    max_err = std::max(max_err, std::abs(v.u - p.exact(v.x.x(), v.x.y())));
  }
  solver.max_over_processes({&max_err, 1});

  const std::vector<double> peak = tspline::petsc::peak_memory_mib();
  if (tspline::petsc::process_rank() != 0) return 0;
  const std::string& k = sol.solver.kind;
  const char* name = k == "CholmodSupernodalLLT"         ? "CHOLMOD"
                     : k == "SimplicialLDLT"             ? "LDLT"
                     : k == "PETSc CG + hypre BoomerAMG" ? "BoomerAMG"
                     : k == "PETSc CG + PETSc GAMG"      ? "GAMG"
                                                         : "CG+IC";
  std::printf("%5d %9zu %9zu %8.3f %11.3f %10.3f %8.3f %-9s %9.1e %9.1e %9.1f %5d %5d %9.1f %8.3f %8.3f\n", level,
              space->num_cells(), space->num_dofs(), space_s, sol.dirichlet_seconds, sol.assembly_seconds,
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
