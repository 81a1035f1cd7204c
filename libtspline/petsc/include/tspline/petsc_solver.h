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
// Distribution. Every process holds the analysis spaces of the patches that
// its block of cells touches and of their neighbours (analysis_space.h; all
// of a single patch). The global cells are split into contiguous blocks
// [r nc / P, (r+1) nc / P).
// The matrix rows are distributed by ranges of a renumbering of the interior
// DOFs: a DOF belongs to the process whose block holds the first cell (lowest
// cell number) of its support, and the DOFs are numbered process by process.
// As the cells of a quadtree are numbered leaf by leaf, a block is a compact
// region. Row i of K is the sum over the cells of its support of their element
// rows, so each process computes every cell in the support of its own rows
// (its block and a border layer that the neighbouring process computes too)
// and keeps only its own rows: no entry is sent. The rows are built in place as
// hypre's ParCSR matrix with the exact pattern (diag: the columns of the own
// rows, local, diagonal entry first; offd: the others through an ascending
// column map), each element row added by one forward scan of the matrix row.
// PETSc takes the matrix over (MatCreateFromParCSR): BoomerAMG uses it without
// a copy (MATHYPRE); for GAMG it is converted in place to AIJ. (Assembling
// through MatSetValues into MATHYPRE went through hypre's auxiliary row
// storage, a second copy of the matrix: 1.79 GB instead of 1.39 GB peak, and
// 1.5x the assembly time, at 1e6 DOFs.)
//
// Solve: CG (the system is SPD) preconditioned by hypre's BoomerAMG (HMIS
// coarsening, ext+i interpolation with P_max 4, one aggressive level) or PETSc's
// GAMG, stopping when ||b - K u|| <= rtol ||b|| (the unpreconditioned residual,
// so that rtol means the same for every preconditioner). PETSC_OPTIONS (e.g.
// "-ksp_monitor -pc_hypre_boomeramg_strong_threshold 0.5") overrides the
// choices (KSPSetFromOptions). The solution is gathered on every process;
// the error norms and the estimator then split the cells over the processes
// (cell_share) and add up (sum_over_processes).

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tspline/analysis/poisson.h"

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

/// The automatic relative tolerance for n interior unknowns:
///   rtol(n) = min(1e-10, max(kAutoRtolFloor, kAutoRtolScale / n^2)).
/// Why n^-2: CG stops at ||b - K u_k|| <= rtol ||b||. For the 2D stiffness matrix
/// of a quasi-uniform space with n ~ h^-2 unknowns, lambda_min(K) ~ h^2 and
/// ||b|| ~ h (n entries of size h^2 f), so the coefficient error is at most
/// ||K^-1|| rtol ||b|| ~ rtol / h and its L2 norm (a factor h) ~ rtol ||u||: the
/// algebraic L2 error does not shrink with h at fixed rtol, while the cubic
/// discretization error does, like h^4 ~ n^-2 for smooth solutions. A
/// tolerance proportional to n^-2 keeps their ratio fixed; the constant is
/// calibrated on the disk (bench/README.md, "IGA Poisson at scale"): at
/// 1.66e5 DOFs rtol 1e-10 / 1e-12 / 1e-13 leave the L2 error 1.2e-3 / 4.6e-8 /
/// 4e-10 relative from the direct solve's; 0.02 / n^2 = 7.5e-13 there leaves
/// 1.7e-8, with 27 % more CG iterations than 1e-10. The floor: CG's true
/// residual stagnates near eps ||K|| ||u|| / ||b|| ~ eps n (both solvers'
/// round-off), so a smaller rtol only adds iterations on the recursive residual. Non-smooth solutions (larger
/// discretization errors) are then solved more accurately than they need.
inline constexpr double kAutoRtolScale = 0.02;
inline constexpr double kAutoRtolFloor = 1e-15;
double automatic_rtol(std::size_t n);

struct IterativeOptions {
  SolverChoice choice = SolverChoice::Auto;
  Preconditioner preconditioner = Preconditioner::BoomerAMG;
  /// Relative residual ||b - K u|| / ||b|| to reach (> 0); unset: automatic_rtol(n)
  /// for the n unknowns of each system.
  std::optional<double> rtol;
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
  std::vector<int> begin(const AnalysisSpace& space, const std::vector<int>& interior, int ni) override;
  void add_cell(std::span<const int> rows, const Eigen::MatrixXd& Kloc, const Eigen::VectorXd& floc) override;
  bool end_assembly(bool ok) override;
  /// \throw NumericalError if CG does not reach rtol within max_iterations (or diverges).
  SolverStats solve(Eigen::VectorXd& u) override;
  /// This process in PETSC_COMM_WORLD.
  int rank() const override;
  int processes() const override;
  /// MPI_Allgatherv over PETSC_COMM_WORLD.
  std::vector<double> gather_to_all(std::span<const double> v) const override;
  /// MPI_Allreduce over PETSC_COMM_WORLD.
  void sum_over_processes(std::span<double> v) const override;
  void max_over_processes(std::span<double> v) const override;

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
