// Analysis space, Dirichlet interpolation, assembly and solve of the IGA Poisson
// problem (see poisson.h).
#include <Eigen/Dense>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <chrono>
#include <exception>
#include <cmath>
#include <array>
#include <span>
#include <sstream>
#include <stdexcept>

#include <algorithm>

#include "tspline/boundary/boundary_map.h"
#include "tspline/detail/quadrature.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/errors.h"
#include "tspline/validity/map_quality.h"
#include "tspline/analysis/poisson.h"
#include "cell_tabulation.h"

#include <Eigen/CholmodSupport>
#include "toolkit/timing.h"

namespace tspline {

namespace {

using toolkit::Clock;
using toolkit::seconds_since;

std::string at(double x, double y) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << x << ", " << y << ")";
  return s.str();
}

double checked(const ScalarField& fn, const char* name, double x, double y) {
  const double v = fn(x, y);
  if (!std::isfinite(v)) throw InputError(std::string(name) + " is not finite at " + at(x, y));
  return v;
}

}  // namespace

// ------------------------------------------------------------------ formulas

Eigen::Matrix2d physical_hessian(const Eigen::Vector2d& grad_x, const Eigen::Matrix2d& hessian_xi,
                                 const MapDerivatives& d) {
  Eigen::Matrix2d hs;  // sum_k g_k Hess_xi(S_k)
  hs(0, 0) = grad_x.dot(d.xixi);
  hs(0, 1) = hs(1, 0) = grad_x.dot(d.xieta);
  hs(1, 1) = grad_x.dot(d.etaeta);
  const Eigen::Matrix2d Jinv = d.J.inverse();
  return Jinv.transpose() * (hessian_xi - hs) * Jinv;
}

SolutionValue evaluate_solution(const PoissonSolution& sol, std::size_t p, int c, const Eigen::Vector2d& uv,
                                int order) {
  return evaluate_solution(sol, p, sol.space->patch(p), c, uv, order);
}

SolutionValue evaluate_solution(const PoissonSolution& sol, std::size_t p, const PatchSpace& sp, int c,
                                const Eigen::Vector2d& uv, int order) {
  const std::span<const int> dofs = sol.space->dofs(p);
  BasisValues bv;
  sp.basis().evaluate(c, uv, bv, order);
  const MapDerivatives d = sol.space->map(p).derivatives(uv, std::max(order, 1), sp.geometry_cell(c));
  SolutionValue out;
  out.x = d.x;
  out.det_j = d.J.determinant();
  Eigen::Vector2d g_xi = Eigen::Vector2d::Zero();
  Eigen::Matrix2d h_xi = Eigen::Matrix2d::Zero();
  for (std::size_t k = 0; k < bv.ids.size(); ++k) {
    const double ca = sol.coefficients[dofs[bv.ids[k]]];
    out.u += ca * bv.R[k];
    if (order >= 1) g_xi += ca * Eigen::Vector2d(bv.R_xi[k], bv.R_eta[k]);
    if (order >= 2) {
      h_xi(0, 0) += ca * bv.R_xixi[k];
      h_xi(0, 1) += ca * bv.R_xieta[k];
      h_xi(1, 1) += ca * bv.R_etaeta[k];
    }
  }
  h_xi(1, 0) = h_xi(0, 1);
  if (order >= 1) out.grad = d.J.transpose().partialPivLu().solve(g_xi);
  if (order >= 2) out.hessian = physical_hessian(out.grad, h_xi, d);
  return out;
}

SolutionValue evaluate_solution(const PoissonSolution& sol, std::size_t p, const Eigen::Vector2d& uv, int order) {
  return evaluate_solution(sol, p, sol.space->patch(p).basis().locate(uv), uv, order);
}

// ------------------------------------------------------------------ solve

namespace {

/// Gauss points of the edges of analysis cell c on `side` of the parameter
/// square (none if c does not touch it): parametric points and weights.
void side_quadrature(const TMesh& mesh, int c, int side, const std::vector<double>& gp, const std::vector<double>& gw,
                     std::vector<std::pair<Eigen::Vector2d, double>>& out) {
  out.clear();
  const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
  Eigen::Vector2d p0, dir;
  switch (static_cast<Side>(side)) {
    case Side::Bottom:
      if (lo.y() != 0.0) return;
      p0 = lo, dir = {hi.x() - lo.x(), 0.0};
      break;
    case Side::Right:
      if (hi.x() != 1.0) return;
      p0 = {1.0, lo.y()}, dir = {0.0, hi.y() - lo.y()};
      break;
    case Side::Top:
      if (hi.y() != 1.0) return;
      p0 = {lo.x(), 1.0}, dir = {hi.x() - lo.x(), 0.0};
      break;
    case Side::Left:
      if (lo.x() != 0.0) return;
      p0 = lo, dir = {0.0, hi.y() - lo.y()};
      break;
  }
  for (std::size_t q = 0; q < gp.size(); ++q) out.emplace_back(p0 + gp[q] * dir, gw[q] * dir.norm());
}

/// Coefficients of the Dirichlet DOFs: L2 projection of g onto their traces on
/// the domain's boundary, physical arc length (see poisson_solver.h). With
/// `distributed`, each process integrates the border edges of its share of the
/// cells, the entries are gathered, and every process solves the (small) system.
void project_dirichlet(const AnalysisSpace& space, const ScalarField& g, PoissonSolution& sol,
                       const InteriorSystemSolver* distributed) {
  const int n = static_cast<int>(space.num_dofs());
  std::vector<int> bidx(n, -1);
  int nb = 0;
  for (int a = 0; a < n; ++a)
    if (space.is_dirichlet(a)) {
      bidx[a] = nb++;
      sol.is_boundary[a] = true;
    }
  if (nb == 0) return;
  // 5 Gauss points: exact for the parametric mass matrix (degree 6); the
  // physical arc length makes the integrand smooth, not polynomial.
  std::vector<double> gp, gw;
  detail::gauss_points_01(5, gp, gw);
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nb);
  BasisValues bv;
  std::vector<std::pair<int, double>> active;
  std::vector<std::pair<Eigen::Vector2d, double>> points;
  const int nc = static_cast<int>(space.num_cells());
  const auto [first, last] = distributed ? distributed->cell_share(nc) : std::pair<int, int>{0, nc};
  for (int gcell = first; gcell < last; ++gcell) {
    const auto [p, c] = space.cell(static_cast<std::size_t>(gcell));
    const PatchSpace& sp = space.patch(p);
    const TSplineMap& map = space.map(p);
    const std::span<const int> dofs = space.dofs(p);
    for (int side = 0; side < 4; ++side) {
      if (space.is_interface_side(p, side)) continue;
      {
        side_quadrature(sp.mesh(), c, side, gp, gw, points);
        for (const auto& [uv, wt] : points) {
          const MapDerivatives d = map.derivatives(uv, 1, sp.geometry_cell(c));
          const double w = wt * (side % 2 == 0 ? d.J.col(0) : d.J.col(1)).norm();
          sp.basis().evaluate(c, uv, bv, 0);
          active.clear();
          for (std::size_t k = 0; k < bv.ids.size(); ++k)
            if (bv.R[k] != 0.0 && bidx[dofs[bv.ids[k]]] >= 0) active.emplace_back(bidx[dofs[bv.ids[k]]], bv.R[k]);
          const double gv = checked(g, "g", d.x.x(), d.x.y());
          for (const auto& [r, vr] : active) {
            rhs[r] += w * gv * vr;
            for (const auto& [s2, vs] : active) trip.emplace_back(r, s2, w * vr * vs);
          }
        }
      }
    }
  }
  if (distributed && distributed->processes() > 1) {  // every process gets every entry
    std::vector<double> mine;
    mine.reserve(3 * trip.size() + static_cast<std::size_t>(nb) + 1);
    mine.push_back(static_cast<double>(trip.size()));
    for (const auto& t : trip) mine.insert(mine.end(), {double(t.row()), double(t.col()), t.value()});
    mine.insert(mine.end(), rhs.data(), rhs.data() + nb);
    const std::vector<double> all = distributed->gather_to_all(mine);
    trip.clear();
    rhs.setZero();
    for (std::size_t k = 0; k < all.size();) {  // each process's part: count, triplets, rhs
      const auto count = static_cast<std::size_t>(all[k++]);
      for (std::size_t t = 0; t < count; ++t, k += 3)
        trip.emplace_back(static_cast<int>(all[k]), static_cast<int>(all[k + 1]), all[k + 2]);
      for (int r = 0; r < nb; ++r) rhs[r] += all[k++];
    }
  }
  Eigen::SparseMatrix<double> M(nb, nb);
  M.setFromTriplets(trip.begin(), trip.end());
  M.makeCompressed();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  ldlt.compute(M);
  if (ldlt.info() != Eigen::Success)
    throw NumericalError("Dirichlet projection: the boundary mass matrix is singular (" + std::to_string(nb) +
                         " boundary functions)");
  const Eigen::VectorXd c = ldlt.solve(rhs);
  if (!c.allFinite() || (M * c - rhs).norm() > 1e-8 * std::max(rhs.norm(), 1e-300))
    throw NumericalError("Dirichlet projection: the boundary mass solve failed");
  for (int a = 0; a < n; ++a)
    if (bidx[a] >= 0) sol.coefficients[a] = c[bidx[a]];
}

SolverStats solve_spd(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b, Eigen::VectorXd& u) {
  SolverStats st;
  const auto t0 = Clock::now();
  const double bn = b.norm();
  // K holds the lower triangle only (see assemble_stiffness).
  auto residual = [&](const Eigen::VectorXd& x) {
    const Eigen::VectorXd Kx = K.selfadjointView<Eigen::Lower>() * x;
    return bn > 0.0 ? (Kx - b).norm() / bn : Kx.norm();
  };
  // A direct solver's answer, taken if it factors K and its residual is small.
  auto solved_by = [&](auto& solver, const char* kind) {
    solver.compute(K);
    if (solver.info() != Eigen::Success) return false;
    u = solver.solve(b);
    st.kind = kind;
    st.relative_residual = residual(u);
    if (solver.info() != Eigen::Success || !u.allFinite() || !(st.relative_residual <= 1e-8)) return false;
    st.seconds = seconds_since(t0);
    return true;
  };
  {
    // Supernodal Cholesky (CHOLMOD, SuiteSparse): uses BLAS-3 on dense
    // supernodes; at 6.7e4 DOFs ~10x faster than Eigen's simplicial LDLT.
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> llt;
    if (solved_by(llt, "CholmodSupernodalLLT")) return st;
  }
  {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
    if (solved_by(ldlt, "SimplicialLDLT")) return st;
  }
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower,
                           Eigen::IncompleteCholesky<double, Eigen::Lower>>
      cg;
  cg.setTolerance(1e-12);
  cg.setMaxIterations(std::max<Eigen::Index>(1000, 10 * K.rows()));
  cg.compute(K);
  if (cg.info() != Eigen::Success) throw NumericalError("Poisson solve: LDLT and the IC preconditioner both failed");
  u = cg.solve(b);
  st.kind = "ConjugateGradient+IncompleteCholesky";
  st.iterations = static_cast<int>(cg.iterations());
  st.relative_residual = residual(u);
  st.seconds = seconds_since(t0);
  if (!u.allFinite() || st.relative_residual > 1e-6)
    throw NumericalError("Poisson solve: no convergence (relative residual " + std::to_string(st.relative_residual) +
                         ")");
  return st;
}

/// Lower-triangle sparsity pattern of the interior stiffness matrix (column-major:
/// column j holds the rows i >= j of the interior DOFs sharing a cell with j),
/// built from the cell function lists without forming triplets (which would
/// cost 16^2 entries per cell: 4 GB at 1e6 cells).
Eigen::SparseMatrix<double> stiffness_pattern(const AnalysisSpace& space, const std::vector<int>& interior, int ni) {
  const std::size_t nc = space.num_cells();
  std::vector<int> g;
  std::vector<std::int64_t> start(static_cast<std::size_t>(ni) + 1, 0);  // DOF -> cells (CSR)
  for (std::size_t c = 0; c < nc; ++c) {
    space.cell_dofs(c, g);
    for (int a : g)
      if (interior[a] >= 0) ++start[interior[a] + 1];
  }
  for (int j = 0; j < ni; ++j) start[j + 1] += start[j];
  std::vector<int> cells(static_cast<std::size_t>(start[ni]));
  {
    std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
    for (std::size_t c = 0; c < nc; ++c) {
      space.cell_dofs(c, g);
      for (int a : g)
        if (interior[a] >= 0) cells[fill[interior[a]]++] = static_cast<int>(c);
    }
  }
  std::vector<int> outer(static_cast<std::size_t>(ni) + 1, 0), inner, mark(ni, -1), rows;
  for (int j = 0; j < ni; ++j) {
    rows.clear();
    for (std::int64_t k = start[j]; k < start[j + 1]; ++k) {
      space.cell_dofs(static_cast<std::size_t>(cells[k]), g);
      for (int a : g) {
        const int i = interior[a];
        if (i >= j && mark[i] != j) {
          mark[i] = j;
          rows.push_back(i);
        }
      }
    }
    std::sort(rows.begin(), rows.end());
    inner.insert(inner.end(), rows.begin(), rows.end());
    outer[j + 1] = static_cast<int>(inner.size());
  }
  const std::vector<double> zeros(inner.size(), 0.0);
  return Eigen::Map<const Eigen::SparseMatrix<double>>(ni, ni, static_cast<Eigen::Index>(inner.size()), outer.data(),
                                                       inner.data(), zeros.data());
}

/// The element system of global analysis cell gc: Kloc (lower triangle) and
/// floc, one row per function of the cell (its patch's
/// basis().functions_on_cell, ascending), with the Dirichlet lift subtracted
/// from floc: floc_r -= sum_{s Dirichlet} K_rs g_s.
class CellKernel {
 public:
  CellKernel(const AnalysisSpace& space, const ScalarField& f, const std::vector<int>& interior,
             const Eigen::VectorXd& coefficients)
      : space_(space), f_(f), interior_(interior), coefficients_(coefficients) {}

  void compute(std::size_t gc) {
    const auto [p, c] = space_.cell(gc);
    const TSplineMap& map = space_.map(p);
    const PatchSpace& sp = space_.patch(p);
    const std::span<const int> dofs = space_.dofs(p);
    const TMesh& mesh = sp.mesh();
    box_quadrature(mesh.cell_min(c), mesh.cell_max(c), 4, qp_, map.basis(), sp.geometry_cell(c));
    cell_.set(map, sp, c, qp_, 1);
    ids = cell_.ids;
    const std::size_t nf = ids.size();
    const auto n = static_cast<Eigen::Index>(nf);
    Kloc.setZero(n, n);
    floc.setZero(n);
    gx_.resize(nf);
    gy_.resize(nf);
    R_.resize(nf);
    for (std::size_t q = 0; q < qp_.size(); ++q) {
      const MapDerivatives d = cell_.geometry(q);
      const double w = qp_[q].weight * std::abs(d.J.determinant());
      const Eigen::Matrix2d JinvT = d.J.inverse().transpose();
      for (std::size_t k = 0; k < nf; ++k) {
        // R = N(x) M(y), grad_xi R = (N'(x) M(y), N(x) M'(y)); physical gradient J^{-T} grad_xi R.
        const detail::Factor &a = cell_.x(q, k), &b = cell_.y(q, k);
        const double r_xi = a.d * b.v, r_eta = a.v * b.d;
        R_[k] = a.v * b.v;
        gx_[k] = JinvT(0, 0) * r_xi + JinvT(0, 1) * r_eta;
        gy_[k] = JinvT(1, 0) * r_xi + JinvT(1, 1) * r_eta;
      }
      // Kloc += w G^T G, lower triangle (K_rs = int grad R_r . grad R_s).
      for (std::size_t s = 0; s < nf; ++s) {
        const double wx = w * gx_[s], wy = w * gy_[s];
        double* col = &Kloc(0, static_cast<Eigen::Index>(s));
        for (std::size_t r = s; r < nf; ++r) col[r] += wx * gx_[r] + wy * gy_[r];
      }
      const double fv = checked(f_, "f", d.x.x(), d.x.y());
      for (std::size_t k = 0; k < nf; ++k) floc[static_cast<Eigen::Index>(k)] += w * fv * R_[k];
    }
    rows.resize(nf);
    for (std::size_t r = 0; r < nf; ++r) rows[r] = interior_[dofs[ids[r]]];
    // Dirichlet DOF s: lift K(r, s) g_s into the load of the interior rows r.
    for (std::size_t s = 0; s < nf; ++s) {
      if (rows[s] >= 0) continue;
      const double gs = coefficients_[dofs[ids[s]]];
      for (std::size_t r = 0; r < nf; ++r)
        if (rows[r] >= 0) floc[static_cast<Eigen::Index>(r)] -= (r >= s ? Kloc(r, s) : Kloc(s, r)) * gs;
    }
  }

  std::span<const int> ids;  ///< the cell's basis functions
  std::vector<int> rows;     ///< their interior numbers (-1: Dirichlet)
  Eigen::MatrixXd Kloc;      ///< lower triangle
  Eigen::VectorXd floc;

 private:
  const AnalysisSpace& space_;
  const ScalarField& f_;
  const std::vector<int>& interior_;
  const Eigen::VectorXd& coefficients_;
  std::vector<QuadraturePoint> qp_;
  detail::CellTabulation cell_;
  std::vector<double> gx_, gy_, R_;
};

/// Interior stiffness matrix (lower triangle) and load vector, with the
/// Dirichlet coefficients (already in `coefficients`) lifted into the load.
Eigen::SparseMatrix<double> assemble_stiffness(const AnalysisSpace& space, const ScalarField& f,
                                               const std::vector<int>& interior, int ni,
                                               const Eigen::VectorXd& coefficients, Eigen::VectorXd& rhs) {
  Eigen::SparseMatrix<double> K = stiffness_pattern(space, interior, ni);
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  double* values = K.valuePtr();
  rhs = Eigen::VectorXd::Zero(ni);
  CellKernel cell(space, f, interior, coefficients);
  std::vector<std::pair<int, int>> order;  // (interior number, row of Kloc), ascending
  for (std::size_t c = 0; c < space.num_cells(); ++c) {
    cell.compute(c);
    order.clear();
    for (std::size_t r = 0; r < cell.rows.size(); ++r)
      if (cell.rows[r] >= 0) order.emplace_back(cell.rows[r], static_cast<int>(r));
    // Glued DOFs are not numbered in the order of a patch's functions: sort, so
    // that the rows of a column are met in the order of the pattern.
    std::sort(order.begin(), order.end());
    for (std::size_t s = 0; s < order.size(); ++s) {
      const auto [js, ks] = order[s];
      rhs[js] += cell.floc[ks];
      int p = outer[js];
      for (std::size_t r = s; r < order.size(); ++r) {
        const auto [ir, kr] = order[r];
        while (inner[p] != ir) ++p;  // present by construction of the pattern
        values[p] += kr >= ks ? cell.Kloc(kr, ks) : cell.Kloc(ks, kr);
      }
    }
  }
  return K;
}

/// The same system handed cell by cell to an external solver, for the cells it
/// asks for. An exception on this process (e.g. f not finite) is rethrown only
/// after end_assembly, so that the other processes are not left waiting.
void assemble_external(const AnalysisSpace& space, const ScalarField& f, const std::vector<int>& interior, int ni,
                       const Eigen::VectorXd& coefficients, InteriorSystemSolver& solver) {
  const std::vector<int> cells = solver.begin(space, interior, ni);
  std::exception_ptr failure;
  try {
    CellKernel cell(space, f, interior, coefficients);
    for (int c : cells) {
      cell.compute(static_cast<std::size_t>(c));
      solver.add_cell(cell.rows, cell.Kloc, cell.floc);
    }
  } catch (...) {
    failure = std::current_exception();
  }
  const bool all_ok = solver.end_assembly(!failure);
  if (failure) std::rethrow_exception(failure);
  if (!all_ok) throw NumericalError("Poisson assembly failed on another process (see its message)");
}

}  // namespace

PoissonSolution solve_poisson(const TSplineMap& map, const TMesh& analysis_mesh, const PoissonProblem& problem) {
  return solve_poisson(std::make_shared<const AnalysisSpace>(map, analysis_mesh), problem);
}

PoissonSolution solve_poisson(std::shared_ptr<const AnalysisSpace> space, const PoissonProblem& problem,
                              InteriorSystemSolver* solver) {
  if (!problem.f) throw InputError("Poisson problem: the source f is missing");
  if (!problem.g) throw InputError("Poisson problem: the Dirichlet data g is missing");
  PoissonSolution sol;
  sol.space = space;
  const AnalysisSpace& sp = *space;
  const int n = static_cast<int>(sp.num_dofs());
  sol.coefficients = Eigen::VectorXd::Zero(n);
  sol.is_boundary.assign(n, false);

  auto t0 = Clock::now();
  project_dirichlet(sp, problem.g, sol, solver);
  sol.dirichlet_seconds = seconds_since(t0);

  // Interior numbering.
  std::vector<int> interior(n, -1);
  int ni = 0;
  for (int a = 0; a < n; ++a)
    if (!sol.is_boundary[a]) interior[a] = ni++;
  sol.interior_dofs = static_cast<std::size_t>(ni);

  if (ni > 0 && solver != nullptr && solver->accepts(static_cast<std::size_t>(ni))) {
    t0 = Clock::now();
    assemble_external(sp, problem.f, interior, ni, sol.coefficients, *solver);
    sol.assembly_seconds = seconds_since(t0);
    Eigen::VectorXd u;
    sol.solver = solver->solve(u);
    for (int a = 0; a < n; ++a)
      if (interior[a] >= 0) sol.coefficients[a] = u[interior[a]];
    return sol;
  }

  // The built-in direct solver assembles every cell (on every process, redundantly).
  if (!sp.holds_all()) sol.space = sp.completed();
  t0 = Clock::now();
  Eigen::VectorXd rhs;
  const Eigen::SparseMatrix<double> K =
      assemble_stiffness(*sol.space, problem.f, interior, ni, sol.coefficients, rhs);
  sol.assembly_seconds = seconds_since(t0);

  if (ni > 0) {
    Eigen::VectorXd u;
    sol.solver = solve_spd(K, rhs, u);
    for (int a = 0; a < n; ++a)
      if (interior[a] >= 0) sol.coefficients[a] = u[interior[a]];
  } else {
    sol.solver.kind = "none";
  }
  return sol;
}

}  // namespace tspline
