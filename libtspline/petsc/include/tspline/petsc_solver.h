#pragma once
// PETSc module of libtspline (target tspline_petsc): the interior system of the
// IGA Poisson solver (poisson.h) solved by PETSc's conjugate gradients with an
// algebraic multigrid preconditioner, assembled and solved in parallel over the
// processes of PETSC_COMM_WORLD (one per MPI rank).
//
// The core library stays Eigen-only; only this module and the programs that use
// it depend on PETSc (and through it on MPI and hypre). The caller initializes
// and finalizes PETSc (PetscInitialize / PetscFinalize; the tspline program does
// it in apps/petsc_session.h). No I/O: errors are exceptions (tspline/errors.h).
//
// Distribution. Every process holds the whole analysis space (T-mesh and basis:
// small next to the matrix). Process r of P assembles the contiguous block of
// cells [r nc / P, (r+1) nc / P). The matrix rows are distributed by ranges of
// a renumbering of the interior DOFs: a DOF belongs to the process that
// assembles the first cell (lowest cell number) in its support, and the DOFs
// are numbered process by process. As the cells of a quadtree are numbered
// leaf by leaf, a cell block is a compact region, and only the element rows of
// DOFs near its border go to another process (MatSetValues stashes them; they
// are sent in MatAssemblyBegin/End). The preallocation is exact (every process
// counts, for its own rows, the columns in and outside its diagonal block).
// With BoomerAMG the matrix is assembled as hypre's own (MATHYPRE), so that
// PCHYPRE uses it without a copy; with GAMG it is a PETSc AIJ matrix.
//
// Solve: CG (the system is SPD) preconditioned by hypre's BoomerAMG (HMIS
// coarsening, ext+i interpolation with P_max 4, one aggressive level) or PETSc's
// GAMG, stopping when ||b - K u|| <= rtol ||b|| (the unpreconditioned residual,
// so that rtol means the same for every preconditioner). PETSC_OPTIONS (e.g.
// "-ksp_monitor -pc_hypre_boomeramg_strong_threshold 0.5") overrides the
// choices (KSPSetFromOptions). The solution is gathered on every process.

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "tspline/poisson.h"

namespace tspline::petsc {

enum class SolverChoice {
  Auto,       ///< direct (the core's CHOLMOD) below auto_threshold unknowns, iterative from there
  Direct,     ///< always the core's direct solver (on every process, redundantly, if several)
  Iterative,  ///< always PETSc CG + AMG
};

enum class Preconditioner {
  BoomerAMG,  ///< hypre BoomerAMG (PCHYPRE)
  GAMG,       ///< PETSc's smoothed-aggregation AMG (PCGAMG)
};

/// Interior unknowns from which `auto` uses the iterative solver: the measured
/// crossover of CHOLMOD and CG + BoomerAMG in time on the benchmark (bench/README.md).
inline constexpr std::size_t kAutoIterativeFrom = 20000;

struct IterativeOptions {
  SolverChoice choice = SolverChoice::Auto;
  Preconditioner preconditioner = Preconditioner::BoomerAMG;
  /// Relative residual ||b - K u|| / ||b|| to reach (> 0). 1e-10: the algebraic
  /// error is then far below the discretization error of the cubic space up to
  /// millions of DOFs; by Galerkin orthogonality the energy error grows only by
  /// the square of their ratio.
  double rtol = 1e-10;
  int max_iterations = 1000;  ///< >= 1; more is a NumericalError
  std::size_t auto_threshold = kAutoIterativeFrom;
};

/// "boomeramg"/"hypre" or "gamg". \throw InputError otherwise.
Preconditioner parse_preconditioner(const std::string& name);
/// "auto", "direct" or "iterative". \throw InputError otherwise.
SolverChoice parse_solver_choice(const std::string& name);

/// The InteriorSystemSolver of poisson.h on PETSc. \pre PETSc is initialized
/// (and stays so while the object lives). All member calls are collective.
class PetscPoissonSolver final : public InteriorSystemSolver {
 public:
  /// \throw InputError for rtol <= 0 (or not finite) or max_iterations < 1.
  explicit PetscPoissonSolver(const IterativeOptions& options);
  ~PetscPoissonSolver() override;
  PetscPoissonSolver(const PetscPoissonSolver&) = delete;
  PetscPoissonSolver& operator=(const PetscPoissonSolver&) = delete;

  bool accepts(std::size_t ni) const override;
  std::vector<int> begin(const AnalysisSpace& space, const std::vector<int>& dof, int ni) override;
  void add_cell(std::span<const int> rows, const Eigen::MatrixXd& Kloc, const Eigen::VectorXd& floc) override;
  bool end_assembly(bool ok) override;
  /// \throw NumericalError if CG does not reach rtol within max_iterations (or diverges).
  SolverStats solve(Eigen::VectorXd& u) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Rank of this process in PETSC_COMM_WORLD and the number of processes.
int process_rank();
int process_count();

/// Peak resident memory (getrusage) of every process so far, MiB, indexed by
/// rank (collective; every process gets all).
std::vector<double> peak_memory_mib();

}  // namespace tspline::petsc
