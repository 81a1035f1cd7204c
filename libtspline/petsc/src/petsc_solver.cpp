// PETSc CG + AMG for the IGA Poisson interior system (see petsc_solver.h).
#include "tspline/petsc_solver.h"

#include <_hypre_parcsr_mv.h>
#include <petscksp.h>
#include <petscmathypre.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <string>

#include "tspline/errors.h"
#include "toolkit/timing.h"

namespace tspline::petsc {

namespace {

using toolkit::Clock;
using toolkit::seconds_since;

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

double automatic_rtol(std::size_t n) {
  const double nn = static_cast<double>(std::max<std::size_t>(n, 1));
  return std::min(1e-10, std::max(kAutoRtolFloor, kAutoRtolScale / (nn * nn)));
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
  // This process's rows, built in place as hypre's ParCSR matrix (see begin()):
  // diag (columns in [row_begin, row_end), local numbers, the diagonal entry
  // first, the others ascending) and offd (the other columns, ascending in
  // col_map, hypre's sorted list of their global numbers).
  hypre_ParCSRMatrix* parcsr = nullptr;
  HYPRE_Int *di = nullptr, *dj = nullptr, *oi = nullptr, *oj = nullptr;
  HYPRE_Complex *dv = nullptr, *ov = nullptr;
  HYPRE_BigInt* col_map = nullptr;
  std::vector<double> load;  // own rows of b
  std::vector<std::pair<PetscInt, int>> cell_cols;  // add_cell scratch: (global column, row of Kloc), sorted

  // The steps of begin(), in order.
  void number_rows(const AnalysisSpace& space, const std::vector<int>& interior, int ni);
  std::vector<int> own_row_cells(const AnalysisSpace& space, const std::vector<int>& interior,
                                 std::vector<std::int64_t>& start, std::vector<int>& cells) const;
  void build_pattern(const AnalysisSpace& space, const std::vector<int>& interior, int ni,
                     const std::vector<std::int64_t>& start, const std::vector<int>& cells);
  bool own(PetscInt g) const { return g >= row_begin && g < row_end; }
  // solve()'s PETSc objects and steps (below).
  class CgRun;

  void release() {
    if (A) MatDestroy(&A);
    if (b) VecDestroy(&b);
    if (parcsr) hypre_ParCSRMatrixDestroy(parcsr);
    A = nullptr;
    b = nullptr;
    parcsr = nullptr;
  }
  ~Impl() { release(); }
};

PetscPoissonSolver::PetscPoissonSolver(const IterativeOptions& options) : impl_(std::make_unique<Impl>()) {
  if (options.rtol && (!(*options.rtol > 0.0) || !std::isfinite(*options.rtol)))
    throw InputError("the iterative solver's relative tolerance must be > 0, got " + g3(*options.rtol));
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

namespace {

// The interior numbers of the functions of cell c (-1: Dirichlet), in a buffer
// reused from call to call.
class CellRows {
 public:
  CellRows(const AnalysisSpace& space, const std::vector<int>& interior) : space_(space), interior_(interior) {}
  const std::vector<int>& operator()(int c) {
    space_.cell_dofs(static_cast<std::size_t>(c), rows_);
    for (int& a : rows_) a = interior_[a];
    return rows_;
  }

 private:
  const AnalysisSpace& space_;
  const std::vector<int>& interior_;
  std::vector<int> rows_;
};

}  // namespace

// Owner of interior DOF i: the process whose block of cells [r nc / P,
// (r+1) nc / P) holds the first cell of its support. Each process finds it in
// its own block (whose patches it holds), the minimum over the processes is
// the first cell. Rows are numbered process by process (perm).
void PetscPoissonSolver::Impl::number_rows(const AnalysisSpace& space, const std::vector<int>& interior, int ni) {
  const int nc = static_cast<int>(space.num_cells());
  const int P = process_count(), R = process_rank();
  CellRows rows_of(space, interior);
  std::vector<int> first_cell(static_cast<std::size_t>(ni), std::numeric_limits<int>::max());
  for (int c = block_start(nc, R, P); c < block_start(nc, R + 1, P); ++c)
    for (int i : rows_of(c))
      if (i >= 0 && first_cell[i] > c) first_cell[i] = c;
  if (P > 1) MPI_Allreduce(MPI_IN_PLACE, first_cell.data(), ni, MPI_INT, MPI_MIN, PETSC_COMM_WORLD);
  std::vector<int> owner(static_cast<std::size_t>(ni));
  std::vector<PetscInt> count(static_cast<std::size_t>(P) + 1, 0);
  std::vector<int> starts(static_cast<std::size_t>(P) + 1);
  for (int q = 0; q <= P; ++q) starts[q] = block_start(nc, q, P);
  for (int i = 0; i < ni; ++i) {  // block of cell c: the last r with starts[r] <= c
    const int c = first_cell[i];
    const int r = static_cast<int>(std::upper_bound(starts.begin(), starts.end() - 1, c) - starts.begin()) - 1;
    owner[i] = std::max(r, 0);
    ++count[owner[i] + 1];
  }
  std::vector<int>().swap(first_cell);
  for (int q = 0; q < P; ++q) count[q + 1] += count[q];  // prefix: first row of each process
  row_begin = count[R];
  row_end = count[R + 1];
  n = ni;
  perm.assign(static_cast<std::size_t>(ni), 0);
  std::vector<PetscInt> next(count.begin(), count.end() - 1);
  for (int i = 0; i < ni; ++i) perm[i] = next[owner[i]]++;
}

// The cells of this process: every cell in the support of an own row, listed
// per own row (CSR: start, cells). Row k of K is the sum over those cells of
// their element rows, so the process adds them up itself and no entry is sent
// to another process; a cell on the border of two processes' rows is computed
// by both (about 1 % of the cells with 2 processes at 1e6 DOFs). Those cells
// lie in the patches this process holds (the patches of its block and their
// neighbours: analysis_space.h). Returns them once each.
std::vector<int> PetscPoissonSolver::Impl::own_row_cells(const AnalysisSpace& space, const std::vector<int>& interior,
                                                         std::vector<std::int64_t>& start,
                                                         std::vector<int>& cells) const {
  const int nc = static_cast<int>(space.num_cells());
  CellRows rows_of(space, interior);
  const PetscInt nloc = row_end - row_begin;
  start.assign(static_cast<std::size_t>(nloc) + 1, 0);
  std::vector<int> cells_mine;
  for (int c = 0; c < nc; ++c) {
    if (!space.holds(space.cell(static_cast<std::size_t>(c)).first)) continue;
    bool mine = false;
    for (int i : rows_of(c))
      if (i >= 0 && own(perm[i])) {
        ++start[perm[i] - row_begin + 1];
        mine = true;
      }
    if (mine) cells_mine.push_back(c);
  }
  for (PetscInt k = 0; k < nloc; ++k) start[k + 1] += start[k];
  cells.assign(static_cast<std::size_t>(start[nloc]), 0);
  std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
  for (int c : cells_mine)
    for (int i : rows_of(c))
      if (i >= 0 && own(perm[i])) cells[fill[perm[i] - row_begin]++] = c;
  return cells_mine;
}

// The own rows' pattern as hypre's ParCSR matrix, values zero. Row k's
// columns: the interior functions of the cells of its support, each once
// (mark), in global numbers, sorted. Pass 1 counts them (and collects the
// off-process ones); pass 2 writes them into hypre's arrays (hypre's
// conventions: diag column indices local, the diagonal entry first in each
// row, which its smoothers rely on; offd column indices into the ascending
// col_map_offd).
void PetscPoissonSolver::Impl::build_pattern(const AnalysisSpace& space, const std::vector<int>& interior, int ni,
                                             const std::vector<std::int64_t>& start, const std::vector<int>& cells) {
  CellRows rows_of(space, interior);
  const PetscInt nloc = row_end - row_begin;
  std::vector<PetscInt> mark(static_cast<std::size_t>(ni), -1), cols;
  const auto row_columns = [&](PetscInt k) {
    cols.clear();
    for (std::int64_t e = start[k]; e < start[k + 1]; ++e)
      for (int i : rows_of(cells[e])) {
        if (i < 0 || mark[i] == k) continue;
        mark[i] = k;
        cols.push_back(perm[i]);
      }
    std::sort(cols.begin(), cols.end());
  };
  std::vector<HYPRE_Int> d_nnz(static_cast<std::size_t>(nloc)), o_nnz(static_cast<std::size_t>(nloc));
  std::vector<HYPRE_BigInt> offd_cols;
  std::int64_t nnz_d = 0, nnz_o = 0;
  for (PetscInt k = 0; k < nloc; ++k) {
    row_columns(k);
    HYPRE_Int nd = 0, no = 0;
    for (PetscInt g : cols) {
      if (own(g)) {
        ++nd;
      } else {
        ++no;
        offd_cols.push_back(static_cast<HYPRE_BigInt>(g));
      }
    }
    d_nnz[k] = nd;
    o_nnz[k] = no;
    nnz_d += nd;
    nnz_o += no;
  }
  std::sort(offd_cols.begin(), offd_cols.end());
  offd_cols.erase(std::unique(offd_cols.begin(), offd_cols.end()), offd_cols.end());
  if (nnz_d > std::numeric_limits<HYPRE_Int>::max() || nnz_o > std::numeric_limits<HYPRE_Int>::max())
    throw NumericalError("iterative solver: " + std::to_string(nnz_d + nnz_o) +
                         " matrix entries on one process exceed hypre's 32-bit index (use more processes)");
  HYPRE_BigInt starts[2] = {static_cast<HYPRE_BigInt>(row_begin), static_cast<HYPRE_BigInt>(row_end)};
  parcsr = hypre_ParCSRMatrixCreate(PETSC_COMM_WORLD, ni, ni, starts, starts, static_cast<HYPRE_Int>(offd_cols.size()),
                                    static_cast<HYPRE_Int>(nnz_d), static_cast<HYPRE_Int>(nnz_o));
  if (!parcsr || hypre_ParCSRMatrixInitialize_v2(parcsr, HYPRE_MEMORY_HOST) != 0)
    throw NumericalError("iterative solver: hypre_ParCSRMatrixCreate failed");
  hypre_CSRMatrix* diag = hypre_ParCSRMatrixDiag(parcsr);
  hypre_CSRMatrix* offd = hypre_ParCSRMatrixOffd(parcsr);
  di = hypre_CSRMatrixI(diag);
  dj = hypre_CSRMatrixJ(diag);
  dv = hypre_CSRMatrixData(diag);
  oi = hypre_CSRMatrixI(offd);
  oj = hypre_CSRMatrixJ(offd);
  ov = hypre_CSRMatrixData(offd);
  col_map = hypre_ParCSRMatrixColMapOffd(parcsr);
  std::copy(offd_cols.begin(), offd_cols.end(), col_map);
  di[0] = 0;
  oi[0] = 0;
  for (PetscInt k = 0; k < nloc; ++k) {
    di[k + 1] = di[k] + d_nnz[k];
    oi[k + 1] = oi[k] + o_nnz[k];
  }
  std::vector<HYPRE_Int>().swap(d_nnz);
  std::vector<HYPRE_Int>().swap(o_nnz);
  std::fill(mark.begin(), mark.end(), -1);
  for (PetscInt k = 0; k < nloc; ++k) {
    row_columns(k);
    HYPRE_Int pd = di[k], po = oi[k];
    dj[pd++] = static_cast<HYPRE_Int>(k);  // the diagonal first
    for (PetscInt g : cols) {
      if (g == row_begin + k) continue;
      if (own(g))
        dj[pd++] = static_cast<HYPRE_Int>(g - row_begin);
      else
        oj[po++] = static_cast<HYPRE_Int>(
            std::lower_bound(offd_cols.begin(), offd_cols.end(), static_cast<HYPRE_BigInt>(g)) - offd_cols.begin());
    }
  }
  std::fill(dv, dv + nnz_d, 0.0);
  std::fill(ov, ov + nnz_o, 0.0);
  load.assign(static_cast<std::size_t>(nloc), 0.0);
}

std::vector<int> PetscPoissonSolver::begin(const AnalysisSpace& space, const std::vector<int>& interior, int ni) {
  Impl& m = *impl_;
  m.release();
#if defined(__GLIBC__)
  // Building the analysis space (hash maps of the basis and T-mesh
  // construction) leaves ~0.35 GB of freed small blocks in the heap at 1e6
  // DOFs, which glibc keeps resident; the matrix arrays below are large
  // (mmap'ed) and would not reuse them. Give them back first.
  malloc_trim(0);
#endif
  m.number_rows(space, interior, ni);
  std::vector<std::int64_t> start;  // own row -> cells (CSR)
  std::vector<int> cells;
  std::vector<int> cells_mine = m.own_row_cells(space, interior, start, cells);
  m.build_pattern(space, interior, ni, start, cells);
  return cells_mine;
}

void PetscPoissonSolver::add_cell(std::span<const int> rows, const Eigen::MatrixXd& Kloc,
                                  const Eigen::VectorXd& floc) {
  Impl& m = *impl_;
  // The interior functions only (rows[k] < 0: Dirichlet), by global column.
  m.cell_cols.clear();
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k] >= 0) m.cell_cols.emplace_back(m.perm[rows[k]], static_cast<int>(k));
  std::sort(m.cell_cols.begin(), m.cell_cols.end());
  // Kloc holds the lower triangle: K(r, s) for r >= s.
  const auto K = [&Kloc](int r, int s) { return r >= s ? Kloc(r, s) : Kloc(s, r); };
  for (const auto& [gi, ki] : m.cell_cols) {
    if (gi < m.row_begin || gi >= m.row_end) continue;  // another process's row
    const PetscInt k = gi - m.row_begin;
    m.load[k] += floc[ki];
    // The row's columns and the cell's are both ascending (diag: after the
    // diagonal entry), so one forward scan of each part finds every position.
    HYPRE_Int pd = m.di[k] + 1, po = m.oi[k];
    for (const auto& [gj, kj] : m.cell_cols) {
      const double v = K(ki, kj);
      if (gj == gi) {
        m.dv[m.di[k]] += v;
      } else if (gj >= m.row_begin && gj < m.row_end) {
        const auto lj = static_cast<HYPRE_Int>(gj - m.row_begin);
        while (pd < m.di[k + 1] && m.dj[pd] != lj) ++pd;
        if (pd == m.di[k + 1]) throw toolkit::InternalError("PETSc assembly: a column outside the preallocated pattern");
        m.dv[pd] += v;
      } else {
        while (po < m.oi[k + 1] && m.col_map[m.oj[po]] != gj) ++po;
        if (po == m.oi[k + 1]) throw toolkit::InternalError("PETSc assembly: a column outside the preallocated pattern");
        m.ov[po] += v;
      }
    }
  }
}

bool PetscPoissonSolver::end_assembly(bool ok) {
  Impl& m = *impl_;
  int mine = ok ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD);
  if (!all) {
    m.release();
    return false;
  }
  hypre_ParCSRMatrixSetNumNonzeros(m.parcsr);
  hypre_ParCSRMatrixSetDNumNonzeros(m.parcsr);
  // PETSc takes the ParCSR matrix over (freed with the Mat). BoomerAMG uses it
  // as it is (MATHYPRE); GAMG needs a PETSc AIJ matrix, converted in place.
  hypre_ParCSRMatrix* parcsr = m.parcsr;
  m.parcsr = nullptr;
  check(MatCreateFromParCSR(parcsr, m.options.preconditioner == Preconditioner::BoomerAMG ? MATHYPRE : MATAIJ,
                            PETSC_OWN_POINTER, &m.A),
        "MatCreateFromParCSR");
  const PetscInt nloc = m.row_end - m.row_begin;
  check(VecCreateMPI(PETSC_COMM_WORLD, nloc, m.n, &m.b), "VecCreateMPI");
  PetscScalar* bv = nullptr;
  check(VecGetArray(m.b, &bv), "VecGetArray");
  std::copy(m.load.begin(), m.load.end(), bv);
  check(VecRestoreArray(m.b, &bv), "VecRestoreArray");
  std::vector<double>().swap(m.load);
  check(MatSetOption(m.A, MAT_SPD, PETSC_TRUE), "MatSetOption(MAT_SPD)");
  return true;
}

namespace {

// The preconditioner p on pc.
void set_preconditioner(PC pc, Preconditioner p) {
  if (p == Preconditioner::BoomerAMG) {
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
}

}  // namespace

// One CG solve of the assembled system: the PETSc objects it creates, freed
// on every exit, and the system with them (the memory is wanted back).
class PetscPoissonSolver::Impl::CgRun {
 public:
  explicit CgRun(Impl& m) : m_(m) {}
  CgRun(const CgRun&) = delete;
  CgRun& operator=(const CgRun&) = delete;
  ~CgRun() {
    if (ksp_) KSPDestroy(&ksp_);
    if (x_) VecDestroy(&x_);
    if (r_) VecDestroy(&r_);
    if (xall_) VecDestroy(&xall_);
    if (gather_) VecScatterDestroy(&gather_);
    m_.release();
  }

  // CG on K with the options' preconditioner, to the relative tolerance rtol.
  void set_up(double rtol) {
    check(KSPCreate(PETSC_COMM_WORLD, &ksp_), "KSPCreate");
    check(KSPSetOperators(ksp_, m_.A, m_.A), "KSPSetOperators");
    check(KSPSetType(ksp_, KSPCG), "KSPSetType");
    PC pc = nullptr;
    check(KSPGetPC(ksp_, &pc), "KSPGetPC");
    set_preconditioner(pc, m_.options.preconditioner);
    // Stop on the true (unpreconditioned) residual: ||b - K u|| <= rtol ||b||.
    check(KSPSetNormType(ksp_, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
    check(KSPSetTolerances(ksp_, rtol, 1e-300, PETSC_DEFAULT, m_.options.max_iterations), "KSPSetTolerances");
    check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
  }

  struct Outcome {
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
    PetscInt iterations = 0;
  };
  // x: CG's solution of K x = b (as far as it got: see reason).
  Outcome solve() {
    check(MatCreateVecs(m_.A, &x_, nullptr), "MatCreateVecs");
    check(KSPSolve(ksp_, m_.b, x_), "KSPSolve");
    Outcome o;
    check(KSPGetConvergedReason(ksp_, &o.reason), "KSPGetConvergedReason");
    check(KSPGetIterationNumber(ksp_, &o.iterations), "KSPGetIterationNumber");
    return o;
  }

  // The true relative residual, recomputed (not the recurrence's estimate).
  double relative_residual() {
    PetscReal bnorm = 0, rnorm = 0;
    check(VecDuplicate(m_.b, &r_), "VecDuplicate");
    check(MatMult(m_.A, x_, r_), "MatMult");
    check(VecAYPX(r_, -1.0, m_.b), "VecAYPX");  // r = b - K x
    check(VecNorm(r_, NORM_2, &rnorm), "VecNorm");
    check(VecNorm(m_.b, NORM_2, &bnorm), "VecNorm");
    return bnorm > 0 ? rnorm / bnorm : rnorm;
  }

  // Gather the solution on every process and undo the renumbering.
  void solution(Eigen::VectorXd& u) {
    check(VecScatterCreateToAll(x_, &gather_, &xall_), "VecScatterCreateToAll");
    check(VecScatterBegin(gather_, x_, xall_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
    check(VecScatterEnd(gather_, x_, xall_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
    const PetscScalar* xa = nullptr;
    check(VecGetArrayRead(xall_, &xa), "VecGetArrayRead");
    u.resize(m_.n);
    for (PetscInt i = 0; i < m_.n; ++i) u[i] = xa[m_.perm[i]];
    check(VecRestoreArrayRead(xall_, &xa), "VecRestoreArrayRead");
  }

 private:
  Impl& m_;
  KSP ksp_ = nullptr;
  Vec x_ = nullptr, r_ = nullptr, xall_ = nullptr;
  VecScatter gather_ = nullptr;
};

SolverStats PetscPoissonSolver::solve(Eigen::VectorXd& u) {
  Impl& m = *impl_;
  const IterativeOptions& o = m.options;
  const auto t0 = Clock::now();
  SolverStats st;
  st.processes = process_count();
  st.kind = std::string("PETSc CG + ") + preconditioner_name(o.preconditioner);
  Impl::CgRun cg(m);  // frees its PETSc objects and the system on every exit
  const double rtol = o.rtol ? *o.rtol : automatic_rtol(static_cast<std::size_t>(m.n));
  st.tolerance = rtol;
  cg.set_up(rtol);
  const auto [reason, its] = cg.solve();
  st.iterations = static_cast<int>(its);
  st.relative_residual = cg.relative_residual();
  if (reason < 0)
    throw NumericalError("iterative solve (" + st.kind + ") did not converge: " + KSPConvergedReasons[reason] +
                         " after " + std::to_string(its) + " iterations (limit " +
                         std::to_string(o.max_iterations) + "), relative residual " +
                         g3(st.relative_residual) + " (rtol " + g3(rtol) + ")");
  cg.solution(u);
  st.seconds = seconds_since(t0);
  return st;
}

int PetscPoissonSolver::rank() const { return process_rank(); }
int PetscPoissonSolver::processes() const { return process_count(); }

std::vector<double> PetscPoissonSolver::gather_to_all(std::span<const double> v) const {
  const int P = process_count();
  if (P == 1) return {v.begin(), v.end()};
  int mine = static_cast<int>(v.size());
  std::vector<int> counts(static_cast<std::size_t>(P)), starts(static_cast<std::size_t>(P) + 1, 0);
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, PETSC_COMM_WORLD);
  for (int q = 0; q < P; ++q) starts[q + 1] = starts[q] + counts[q];
  std::vector<double> all(static_cast<std::size_t>(starts[P]));
  MPI_Allgatherv(v.data(), mine, MPI_DOUBLE, all.data(), counts.data(), starts.data(), MPI_DOUBLE, PETSC_COMM_WORLD);
  return all;
}

void PetscPoissonSolver::sum_over_processes(std::span<double> v) const {
  if (process_count() > 1 && !v.empty())
    MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
}

void PetscPoissonSolver::max_over_processes(std::span<double> v) const {
  if (process_count() > 1 && !v.empty())
    MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
}

}  // namespace tspline::petsc
