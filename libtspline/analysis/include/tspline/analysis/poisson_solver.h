#pragma once
// Isogeometric Poisson solver (the residual estimator is poisson_estimator.h,
// the adaptive loop poisson_adaptive.h, all three together poisson.h)
// (Brovka, López, Escobar, Cascón, Montenegro, "A new method for T-spline parameterization
// of complex 2D geometries", Engineering with Computers 2014, Sect. 7.2; README.md,
// "tspline poisson").
//
//   -Laplace(u) = f in Omega = S([0,1]^2),   u = g on the boundary of Omega.
//
// Analysis space: cubic hierarchical B-splines (hierarchical_basis.h) on an
// ANALYSIS T-mesh. It starts equal to the geometry's T-mesh and is refined
// independently; the geometry map S stays the one of the parameterization, so
// the method is NOT isoparametric (as in the paper). Every analysis cell lies
// inside one geometry cell, located once per cell, so that S and its derivatives
// are evaluated with the geometry cell's function list.
// Deviation from the paper (which uses the T-spline blending functions of the
// analysis T-mesh): on T-meshes with hanging vertices those do not reproduce
// linear functions and are not nested under refinement, which costs the
// convergence rates (measured: about h^2 in L2 and h in H1 on curved domains);
// the hierarchical B-splines of the same quadtree contain all cubic polynomials
// and converge at the optimal rates h^4 (L2) and h^3 (H1).
//
// Discretization (Galerkin):
//  * stiffness K_ab = int grad R_a . grad R_b dx, load b_a = int f R_a dx, both with
//    4x4 Gauss points per piece of each analysis cell: the cell split by the knot
//    lines of the geometry's functions that cross it (box_quadrature() in
//    bezier_extraction.h), so that S is smooth on every piece; the analysis
//    functions are polynomial on the whole cell. grad_x R = J^{-T} grad_xi R,
//    weight |det J|.
//  * Dirichlet data by L2 PROJECTION on the border: the boundary functions B are
//    those that do not vanish on the border of [0,1]^2 (HierarchicalFunction::
//    on_border); their coefficients solve  sum_{b in B} c_b <R_b, R_a> = <g o S, R_a>,
//    a in B, with <u, v> the integral over the border of the parameter square
//    (parametric arc length, 5 Gauss points per border cell edge, exact for the
//    mass matrix). Interior functions vanish on the border, so they do not
//    enter. Those DOFs are then eliminated (lifted into the right-hand side); the
//    interior system is symmetric positive definite.
//  * Solve: CHOLMOD's supernodal Cholesky (SuiteSparse); if it fails, Eigen's
//    SimplicialLDLT; if that fails too, conjugate gradients
//    with an incomplete Cholesky preconditioner. Or, when an InteriorSystemSolver
//    is given (e.g. the PETSc module, tspline/petsc_solver.h) and accepts the
//    size, the element matrices of the cells it asks for are handed to it and it
//    solves (iteratively, possibly distributed over processes).
//
// Errors (when an exact solution is given): L2 and H1-seminorm, 6x6 Gauss points per
// piece of each analysis cell (as above). If the exact gradient is not given it is computed by central
// differences with the absolute step kGradientStep (error ~ step^2 |u'''|/6 plus
// round-off ~ eps |u| / step).
//
// Errors and estimator (poisson_estimator.h) evaluate u_h and S per cell from
// the univariate B-spline factors tabulated at the distinct quadrature
// coordinates (the values of evaluate_solution()); with a distributed solver
// each process integrates its cell_share() and the sums are combined
// (InteriorSystemSolver).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tspline/analysis/hierarchical_basis.h"
#include "tspline/spline/tspline_map.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {


using ScalarField = std::function<double(double, double)>;
using VectorField = std::function<Eigen::Vector2d(double, double)>;

/// Central-difference step for the exact gradient when none is given.
inline constexpr double kGradientStep = 1e-5;

struct PoissonProblem {
  ScalarField f;               ///< source (required)
  ScalarField g;               ///< Dirichlet data (required)
  ScalarField exact;           ///< exact solution (optional: enables errors)
  VectorField exact_gradient;  ///< its gradient (optional: central differences if absent)
};

/// The analysis space: T-mesh, its basis, and per analysis cell its geometry cell.
class AnalysisSpace {
 public:
  /// \pre analysis_mesh has topology and refines map.mesh() (each cell inside one
  /// geometry cell). \throw InputError otherwise.
  AnalysisSpace(const TSplineMap& map, TMesh analysis_mesh);
  const TMesh& mesh() const { return *mesh_; }
  const HierarchicalBasis& basis() const { return *basis_; }
  int geometry_cell(int c) const { return geometry_cell_[c]; }
  std::size_t num_dofs() const { return basis_->size(); }

 private:
  std::unique_ptr<TMesh> mesh_;  // heap: the basis keeps a pointer to it
  std::unique_ptr<HierarchicalBasis> basis_;
  std::vector<int> geometry_cell_;
};

struct SolverStats {
  std::string kind;                ///< "CholmodSupernodalLLT", "SimplicialLDLT" or "ConjugateGradient+IncompleteCholesky"
  double seconds = 0.0;            ///< factorization + solve
  double relative_residual = 0.0;  ///< ||K u - b|| / ||b|| of the interior system (0 if b = 0)
  int iterations = 0;              ///< CG iterations (0 for the direct solver)
  int processes = 1;               ///< processes that shared the solve
  double tolerance = 0.0;          ///< an iterative solver's relative tolerance (0 for the direct solver)
};

/// An external solver of the interior system K u = b (K symmetric positive
/// definite), fed element by element. The core stays free of it: the PETSc
/// module (target tspline_petsc) implements it. All calls are made on every
/// process of a distributed run, in the same order (collective).
class InteriorSystemSolver {
 public:
  virtual ~InteriorSystemSolver() = default;
  /// Whether it solves a system of ni unknowns; if not, the built-in direct solver does.
  virtual bool accepts(std::size_t ni) const = 0;
  /// Starts the system: dof[a] = interior number of basis function a (-1 for a
  /// Dirichlet function), ni unknowns. Returns the cells this process
  /// assembles, ascending (a distributed solver may ask two processes for the
  /// same cell, each keeping the rows it owns).
  virtual std::vector<int> begin(const AnalysisSpace& space, const std::vector<int>& dof, int ni) = 0;
  /// One cell's contribution: rows[k] = interior number of the cell's k-th
  /// function (-1: Dirichlet, to be ignored); Kloc its element stiffness matrix
  /// (LOWER triangle filled, K(r, s) for r >= s); floc its load with the
  /// Dirichlet lift already subtracted.
  virtual void add_cell(std::span<const int> rows, const Eigen::MatrixXd& Kloc, const Eigen::VectorXd& floc) = 0;
  /// Ends the assembly; ok = false if this process failed. Returns whether
  /// every process succeeded.
  virtual bool end_assembly(bool ok) = 0;
  /// Solves; u receives all ni interior values (on every process). \throw
  /// NumericalError if the solve does not converge.
  virtual SolverStats solve(Eigen::VectorXd& u) = 0;
  /// The share [first, last) of nc cells whose error and estimator terms this
  /// process computes (compute_errors, estimate_cells); default: all of them.
  virtual std::pair<int, int> cell_share(int nc) const { return {0, nc}; }
  /// Sums (or takes the maximum of) v element-wise over the processes, in place,
  /// the result on every process (collective); default: one process, v stays.
  virtual void sum_over_processes(std::span<double> v) const { (void)v; }
  virtual void max_over_processes(std::span<double> v) const { (void)v; }
};

struct PoissonSolution {
  std::shared_ptr<const AnalysisSpace> space;
  Eigen::VectorXd coefficients;        ///< one per basis function (size space->num_dofs())
  std::vector<bool> is_boundary;       ///< Dirichlet DOFs
  std::size_t interior_dofs = 0;       ///< unknowns of the solved system
  SolverStats solver;
  double assembly_seconds = 0.0;
  double dirichlet_seconds = 0.0;
};

/// Value, gradient and Hessian of u_h at a point in physical coordinates.
struct SolutionValue {
  Eigen::Vector2d x = Eigen::Vector2d::Zero();  ///< S(uv)
  double u = 0.0;
  Eigen::Vector2d grad = Eigen::Vector2d::Zero();
  Eigen::Matrix2d hessian = Eigen::Matrix2d::Zero();  ///< only for order 2
  double det_j = 0.0;
};

/// Physical Hessian from the parametric one: with g = grad_x u,
///   H_x = J^{-T} (H_xi - sum_k g_k Hess_xi(S_k)) J^{-1},
/// derived from d2u/dxi_i dxi_j = J^T H_x J + sum_k g_k d2S_k/dxi_i dxi_j.
/// \pre d holds second derivatives.
Eigen::Matrix2d physical_hessian(const Eigen::Vector2d& grad_x, const Eigen::Matrix2d& hessian_xi,
                                 const MapDerivatives& d);

/// Solves the problem on the given analysis T-mesh (a refinement of map.mesh()).
/// \throw InputError if f or g are missing or produce a non-finite value;
/// NumericalError if the Dirichlet system or both solvers fail.
PoissonSolution solve_poisson(const TSplineMap& map, const TMesh& analysis_mesh, const PoissonProblem& problem);
/// Same on an already built analysis space (built with the same map).
PoissonSolution solve_poisson(const TSplineMap& map, std::shared_ptr<const AnalysisSpace> space,
                              const PoissonProblem& problem);
/// Same, with an external solver of the interior system (null: the built-in
/// direct solver); it is used if it accepts the number of unknowns.
PoissonSolution solve_poisson(const TSplineMap& map, std::shared_ptr<const AnalysisSpace> space,
                              const PoissonProblem& problem, InteriorSystemSolver* solver);

/// u_h at parametric point uv of analysis cell c (order 0, 1 or 2).
SolutionValue evaluate_solution(const TSplineMap& map, const PoissonSolution& sol, int c, const Eigen::Vector2d& uv,
                                int order = 1);

struct PoissonErrors {
  double l2 = 0.0;             ///< ||u - u_h||_L2
  double h1 = 0.0;             ///< |u - u_h|_H1 (seminorm)
  double l2_exact = 0.0;       ///< ||u||_L2
  double h1_exact = 0.0;       ///< |u|_H1
  double max_abs_at_qp = 0.0;  ///< max |u - u_h| over the quadrature points
};

/// \throw InputError if problem.exact is missing. With `distributed` (collective
/// then), each process integrates its cell_share() and the sums are combined
/// over the processes (the same result up to the order of the additions).
PoissonErrors compute_errors(const TSplineMap& map, const PoissonSolution& sol, const PoissonProblem& problem,
                             const InteriorSystemSolver* distributed = nullptr);

}  // namespace tspline
