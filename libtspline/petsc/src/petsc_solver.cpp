// PETSc CG + AMG for the IGA Poisson interior system (see petsc_solver.h).
#include "tspline/petsc_solver.h"

#include <petscksp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "tspline/errors.h"

namespace tspline::petsc {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// Turns a PETSc error code into a NumericalError with PETSc's message.
void check(PetscErrorCode ierr, const char* what) {
  if (ierr == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(ierr, &text, nullptr);
  throw NumericalError(std::string("PETSc: ") + what + " failed" + (text ? std::string(": ") + text : ""));
}

/// First cell of process r's contiguous block of nc cells split over p processes.
int block_start(int nc, int r, int p) {
  return static_cast<int>(static_cast<std::int64_t>(nc) * r / p);
}

/// A number for messages (%g, 3 significant digits).
std::string g3(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

const char* preconditioner_name(Preconditioner p) {
  return p == Preconditioner::BoomerAMG ? "hypre BoomerAMG" : "PETSc GAMG";
}

}  // namespace

Preconditioner parse_preconditioner(const std::string& name) {
  if (name == "boomeramg" || name == "hypre") return Preconditioner::BoomerAMG;
  if (name == "gamg") return Preconditioner::GAMG;
  throw InputError("unknown preconditioner '" + name + "' (expected boomeramg or gamg)");
}

SolverChoice parse_solver_choice(const std::string& name) {
  if (name == "auto") return SolverChoice::Auto;
  if (name == "direct") return SolverChoice::Direct;
  if (name == "iterative") return SolverChoice::Iterative;
  throw InputError("unknown solver '" + name + "' (expected auto, direct or iterative)");
}

int process_rank() {
  PetscMPIInt r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}

int process_count() {
  PetscMPIInt p = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &p);
  return p;
}

std::vector<double> peak_memory_mib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  double mine = static_cast<double>(ru.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
  std::vector<double> all(static_cast<std::size_t>(process_count()));
  MPI_Allgather(&mine, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, PETSC_COMM_WORLD);
  return all;
}

struct PetscPoissonSolver::Impl {
  IterativeOptions options;
  Mat A = nullptr;
  Vec b = nullptr;
  std::vector<PetscInt> perm;  // interior DOF -> global row (process-by-process numbering)
  PetscInt row_begin = 0, row_end = 0, n = 0;
  std::vector<std::size_t> local;   // add_cell scratch: the cell's interior functions
  std::vector<PetscInt> g;          // add_cell scratch: their global rows
  std::vector<PetscScalar> kv, fv;  // add_cell scratch: full element matrix (row-major) and load

  void release() {
    if (A) MatDestroy(&A);
    if (b) VecDestroy(&b);
    A = nullptr;
    b = nullptr;
  }
  ~Impl() { release(); }
};

PetscPoissonSolver::PetscPoissonSolver(const IterativeOptions& options) : impl_(std::make_unique<Impl>()) {
  if (!(options.rtol > 0.0) || !std::isfinite(options.rtol))
    throw InputError("the iterative solver's relative tolerance must be > 0, got " + g3(options.rtol));
  if (options.max_iterations < 1)
    throw InputError("the iterative solver's iteration limit must be at least 1, got " +
                     std::to_string(options.max_iterations));
  impl_->options = options;
}

PetscPoissonSolver::~PetscPoissonSolver() = default;

bool PetscPoissonSolver::accepts(std::size_t ni) const {
  switch (impl_->options.choice) {
    case SolverChoice::Direct: return false;
    case SolverChoice::Iterative: return true;
    case SolverChoice::Auto: break;
  }
  return ni >= impl_->options.auto_threshold;
}

std::pair<int, int> PetscPoissonSolver::begin(const AnalysisSpace& space, const std::vector<int>& dof, int ni) {
  Impl& m = *impl_;
  m.release();
  const HierarchicalBasis& basis = space.basis();
  const int nc = static_cast<int>(space.mesh().num_cells());
  const int P = process_count(), R = process_rank();
  const int c0 = block_start(nc, R, P), c1 = block_start(nc, R + 1, P);

  // Owner of interior DOF i: the process whose block holds the first cell of its support.
  std::vector<int> first_cell(static_cast<std::size_t>(ni), -1);
  for (int c = 0; c < nc; ++c)
    for (int a : basis.functions_on_cell(c))
      if (dof[a] >= 0 && first_cell[dof[a]] < 0) first_cell[dof[a]] = c;
  std::vector<int> owner(static_cast<std::size_t>(ni));
  std::vector<PetscInt> count(static_cast<std::size_t>(P) + 1, 0);
  {
    int r = 0;  // block of cell c: the last r with block_start(r) <= c (blocks ascend with r)
    std::vector<int> starts(static_cast<std::size_t>(P) + 1);
    for (int q = 0; q <= P; ++q) starts[q] = block_start(nc, q, P);
    for (int i = 0; i < ni; ++i) {
      const int c = first_cell[i];
      r = static_cast<int>(std::upper_bound(starts.begin(), starts.end() - 1, c) - starts.begin()) - 1;
      owner[i] = std::max(r, 0);
      ++count[owner[i] + 1];
    }
  }
  for (int q = 0; q < P; ++q) count[q + 1] += count[q];  // prefix: first row of each process
  m.row_begin = count[R];
  m.row_end = count[R + 1];
  m.n = ni;
  m.perm.assign(static_cast<std::size_t>(ni), 0);
  {
    std::vector<PetscInt> next(count.begin(), count.end() - 1);
    for (int i = 0; i < ni; ++i) m.perm[i] = next[owner[i]]++;
  }

  // Exact preallocation: for each own row, the distinct columns of the cells in
  // its support, inside ([row_begin, row_end)) and outside the diagonal block.
  const PetscInt nloc = m.row_end - m.row_begin;
  std::vector<std::int64_t> start(static_cast<std::size_t>(nloc) + 1, 0);  // own row -> cells (CSR)
  for (int c = 0; c < nc; ++c)
    for (int a : basis.functions_on_cell(c))
      if (dof[a] >= 0) {
        const PetscInt row = m.perm[dof[a]];
        if (row >= m.row_begin && row < m.row_end) ++start[row - m.row_begin + 1];
      }
  for (PetscInt k = 0; k < nloc; ++k) start[k + 1] += start[k];
  std::vector<int> cells(static_cast<std::size_t>(start[nloc]));
  {
    std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
    for (int c = 0; c < nc; ++c)
      for (int a : basis.functions_on_cell(c))
        if (dof[a] >= 0) {
          const PetscInt row = m.perm[dof[a]];
          if (row >= m.row_begin && row < m.row_end) cells[fill[row - m.row_begin]++] = c;
        }
  }
  std::vector<PetscInt> d_nnz(static_cast<std::size_t>(nloc), 0), o_nnz(static_cast<std::size_t>(nloc), 0);
  std::vector<PetscInt> mark(static_cast<std::size_t>(ni), -1);
  for (PetscInt k = 0; k < nloc; ++k)
    for (std::int64_t e = start[k]; e < start[k + 1]; ++e)
      for (int a : basis.functions_on_cell(cells[e])) {
        if (dof[a] < 0 || mark[dof[a]] == k) continue;
        mark[dof[a]] = k;
        const PetscInt col = m.perm[dof[a]];
        ++(col >= m.row_begin && col < m.row_end ? d_nnz[k] : o_nnz[k]);
      }

  check(MatCreate(PETSC_COMM_WORLD, &m.A), "MatCreate");
  check(MatSetSizes(m.A, nloc, nloc, ni, ni), "MatSetSizes");
  if (m.options.preconditioner == Preconditioner::BoomerAMG) {
    // Assembled directly as hypre's ParCSR matrix: PCHYPRE would otherwise copy
    // an AIJ matrix into one, and both would live through the solve (at 1e6
    // DOFs ~0.6 GB each: 49 entries per row).
    check(MatSetType(m.A, MATHYPRE), "MatSetType(hypre)");
    check(MatHYPRESetPreallocation(m.A, 0, d_nnz.data(), 0, o_nnz.data()), "MatHYPRESetPreallocation");
  } else {
    check(MatSetType(m.A, MATAIJ), "MatSetType");
    check(MatSeqAIJSetPreallocation(m.A, 0, d_nnz.data()), "MatSeqAIJSetPreallocation");
    check(MatMPIAIJSetPreallocation(m.A, 0, d_nnz.data(), 0, o_nnz.data()), "MatMPIAIJSetPreallocation");
    check(MatSetOption(m.A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
  }
  check(VecCreateMPI(PETSC_COMM_WORLD, nloc, ni, &m.b), "VecCreateMPI");
  check(VecSet(m.b, 0.0), "VecSet");
  return {c0, c1};
}

void PetscPoissonSolver::add_cell(std::span<const int> rows, const Eigen::MatrixXd& Kloc,
                                  const Eigen::VectorXd& floc) {
  Impl& m = *impl_;
  // The interior functions only (rows[k] < 0: Dirichlet), in global numbering.
  m.local.clear();
  m.g.clear();
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k] >= 0) {
      m.local.push_back(k);
      m.g.push_back(m.perm[rows[k]]);
    }
  const std::size_t nf = m.local.size();
  m.kv.resize(nf * nf);
  m.fv.resize(nf);
  for (std::size_t i = 0; i < nf; ++i) {  // symmetric: the lower triangle mirrored, row-major
    const std::size_t r = m.local[i];
    m.fv[i] = floc[static_cast<Eigen::Index>(r)];
    for (std::size_t j = 0; j < nf; ++j) {
      const std::size_t s = m.local[j];
      m.kv[i * nf + j] = r >= s ? Kloc(r, s) : Kloc(s, r);
    }
  }
  const auto n = static_cast<PetscInt>(nf);
  check(MatSetValues(m.A, n, m.g.data(), n, m.g.data(), m.kv.data(), ADD_VALUES), "MatSetValues");
  check(VecSetValues(m.b, n, m.g.data(), m.fv.data(), ADD_VALUES), "VecSetValues");
}

bool PetscPoissonSolver::end_assembly(bool ok) {
  Impl& m = *impl_;
  int mine = ok ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD);
  if (!all) {
    m.release();
    return false;
  }
  check(MatAssemblyBegin(m.A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(m.A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  check(VecAssemblyBegin(m.b), "VecAssemblyBegin");
  check(VecAssemblyEnd(m.b), "VecAssemblyEnd");
  check(MatSetOption(m.A, MAT_SPD, PETSC_TRUE), "MatSetOption(MAT_SPD)");
  return true;
}

SolverStats PetscPoissonSolver::solve(Eigen::VectorXd& u) {
  Impl& m = *impl_;
  const IterativeOptions& o = m.options;
  const auto t0 = Clock::now();
  SolverStats st;
  st.processes = process_count();
  st.kind = std::string("PETSc CG + ") + preconditioner_name(o.preconditioner);

  KSP ksp = nullptr;
  Vec x = nullptr, r = nullptr, xall = nullptr;
  VecScatter gather = nullptr;
  struct Cleanup {  // frees the PETSc objects on every exit (the system too: the memory is wanted back)
    KSP& ksp;
    Vec &x, &r, &xall;
    VecScatter& gather;
    Impl& m;
    ~Cleanup() {
      if (ksp) KSPDestroy(&ksp);
      if (x) VecDestroy(&x);
      if (r) VecDestroy(&r);
      if (xall) VecDestroy(&xall);
      if (gather) VecScatterDestroy(&gather);
      m.release();
    }
  } cleanup{ksp, x, r, xall, gather, m};

  check(KSPCreate(PETSC_COMM_WORLD, &ksp), "KSPCreate");
  check(KSPSetOperators(ksp, m.A, m.A), "KSPSetOperators");
  check(KSPSetType(ksp, KSPCG), "KSPSetType");
  PC pc = nullptr;
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  if (o.preconditioner == Preconditioner::BoomerAMG) {
    check(PCSetType(pc, PCHYPRE), "PCSetType(hypre)");
    check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
    // PETSc's BoomerAMG defaults (Falgout coarsening, classical interpolation)
    // build dense coarse operators from the 49-point stencils of cubic splines:
    // at 6.7e4 DOFs 3.9 s for 14 iterations. HMIS coarsening, extended+i
    // interpolation truncated to 4 entries per row and one level of aggressive
    // coarsening: 0.8 s for 17 (bench/README.md). PCHYPRE reads these from the
    // options database only, so they are put there unless already given
    // (PETSC_OPTIONS wins).
    static const char* const kBoomerAMG[][2] = {{"-pc_hypre_boomeramg_coarsen_type", "HMIS"},
                                                {"-pc_hypre_boomeramg_interp_type", "ext+i"},
                                                {"-pc_hypre_boomeramg_P_max", "4"},
                                                {"-pc_hypre_boomeramg_agg_nl", "1"}};
    for (const auto& [name, value] : kBoomerAMG) {
      PetscBool given = PETSC_FALSE;
      check(PetscOptionsHasName(nullptr, nullptr, name, &given), "PetscOptionsHasName");
      if (!given) check(PetscOptionsSetValue(nullptr, name, value), "PetscOptionsSetValue");
    }
  } else {
    check(PCSetType(pc, PCGAMG), "PCSetType(gamg)");
  }
  // Stop on the true (unpreconditioned) residual: ||b - K u|| <= rtol ||b||.
  check(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
  check(KSPSetTolerances(ksp, o.rtol, 1e-300, PETSC_DEFAULT, o.max_iterations), "KSPSetTolerances");
  check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
  check(MatCreateVecs(m.A, &x, nullptr), "MatCreateVecs");
  check(KSPSolve(ksp, m.b, x), "KSPSolve");

  KSPConvergedReason reason;
  PetscInt its = 0;
  check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
  check(KSPGetIterationNumber(ksp, &its), "KSPGetIterationNumber");
  st.iterations = static_cast<int>(its);
  // The true relative residual, recomputed (not the recurrence's estimate).
  PetscReal bnorm = 0, rnorm = 0;
  check(VecDuplicate(m.b, &r), "VecDuplicate");
  check(MatMult(m.A, x, r), "MatMult");
  check(VecAYPX(r, -1.0, m.b), "VecAYPX");  // r = b - K x
  check(VecNorm(r, NORM_2, &rnorm), "VecNorm");
  check(VecNorm(m.b, NORM_2, &bnorm), "VecNorm");
  st.relative_residual = bnorm > 0 ? rnorm / bnorm : rnorm;
  if (reason < 0)
    throw NumericalError("iterative solve (" + st.kind + ") did not converge: " + KSPConvergedReasons[reason] +
                         " after " + std::to_string(its) + " iterations (limit " +
                         std::to_string(o.max_iterations) + "), relative residual " +
                         g3(st.relative_residual) + " (rtol " + g3(o.rtol) + ")");

  // Gather the solution on every process and undo the renumbering.
  check(VecScatterCreateToAll(x, &gather, &xall), "VecScatterCreateToAll");
  check(VecScatterBegin(gather, x, xall, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  check(VecScatterEnd(gather, x, xall, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* xa = nullptr;
  check(VecGetArrayRead(xall, &xa), "VecGetArrayRead");
  u.resize(m.n);
  for (PetscInt i = 0; i < m.n; ++i) u[i] = xa[m.perm[i]];
  check(VecRestoreArrayRead(xall, &xa), "VecRestoreArrayRead");
  st.seconds = seconds_since(t0);
  return st;
}

}  // namespace tspline::petsc
