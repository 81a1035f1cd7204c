#pragma once
// Isogeometric Poisson solver (the residual estimator is poisson_estimator.h,
// the adaptive loop poisson_adaptive.h, all three together poisson.h)
// (Brovka, López, Escobar, Cascón, Montenegro, "A new method for T-spline parameterization
// of complex 2D geometries", Engineering with Computers 2014, Sect. 7.2;
// docs/poisson.md).
//
//   -Laplace(u) = f in Omega = S([0,1]^2),   u = g on the boundary of Omega.
//
// Analysis space (analysis_space.h): on a map of 1 to n patches, cubic
// hierarchical B-splines (hierarchical_basis.h) per patch on an ANALYSIS
// T-mesh, glued C0 across the interfaces (one unknown per glued pair). The
// analysis T-meshes start as the geometry's T-meshes refined to their Bezier
// elements (AnalysisGeometry::meshes) and are refined independently; the geometry map S stays the one of the parameterization, so
// the method is NOT isoparametric (as in the paper). A single map is the case
// of one patch; there is no other path.
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
//  * Dirichlet data by L2 PROJECTION on the domain's boundary: the Dirichlet
//    DOFs B are the global functions non-zero on a patch side that is not an
//    interface (AnalysisSpace::is_dirichlet); their coefficients solve
//    sum_{b in B} c_b <R_b, R_a> = <g, R_a>, a in B, with <u, v> the integral
//    over those sides with PHYSICAL arc length (5 Gauss points per border cell
//    edge), so that a DOF shared by two patches gets one value whatever their
//    parameterizations. The other functions vanish there. Those DOFs are then
//    eliminated (lifted into the right-hand side); the interior system is
//    symmetric positive definite.
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
// Cells are visited in the global numbering of AnalysisSpace (patch by patch).
// Errors and estimator (poisson_estimator.h) evaluate u_h and S per cell from
// the univariate B-spline factors tabulated at the distinct quadrature
// coordinates (the values of evaluate_solution()); with a distributed solver
// each process integrates its cell_share() and the sums are combined
// (InteriorSystemSolver).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tspline/analysis/analysis_space.h"
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
  /// Starts the system: interior[g] = interior number of global DOF g of the
  /// space (-1 for a Dirichlet DOF), ni unknowns. Returns the global cells
  /// (AnalysisSpace numbering) this process assembles, ascending (a
  /// distributed solver may ask two processes for the same cell, each keeping
  /// the rows it owns).
  virtual std::vector<int> begin(const AnalysisSpace& space, const std::vector<int>& interior, int ni) = 0;
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
  /// This process and the number of processes (default: 0 of 1); the spaces
  /// of the adaptive loop are distributed accordingly (analysis_space.h).
  virtual int rank() const { return 0; }
  virtual int processes() const { return 1; }
  /// The share [first, last) of nc cells whose error, estimator and Dirichlet
  /// terms this process computes: AnalysisSpace::block(rank()).
  std::pair<int, int> cell_share(int nc) const {
    const auto share = [&](int r) {
      return static_cast<int>(static_cast<std::int64_t>(nc) * r / processes());
    };
    return {share(rank()), share(rank() + 1)};
  }
  /// Every process's v, concatenated in rank order, on every process (collective).
  virtual std::vector<double> gather_to_all(std::span<const double> v) const { return {v.begin(), v.end()}; }
  /// Sums (or takes the maximum of) v element-wise over the processes, in place,
  /// the result on every process (collective); default: one process, v stays.
  virtual void sum_over_processes(std::span<double> v) const { (void)v; }
  virtual void max_over_processes(std::span<double> v) const { (void)v; }
};

struct PoissonSolution {
  std::shared_ptr<const AnalysisSpace> space;
  Eigen::VectorXd coefficients;        ///< one per global DOF (size space->num_dofs())
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

/// Solves the problem on a space; with an external solver of the interior
/// system (null: the built-in direct solver), used if it accepts the number of unknowns.
/// \throw InputError if f or g are missing or produce a non-finite value;
/// NumericalError if the Dirichlet system or the solvers fail.
PoissonSolution solve_poisson(std::shared_ptr<const AnalysisSpace> space, const PoissonProblem& problem,
                              InteriorSystemSolver* solver = nullptr);
/// Same on a single map and its analysis T-mesh (a refinement of map.mesh()).
PoissonSolution solve_poisson(const TSplineMap& map, const TMesh& analysis_mesh, const PoissonProblem& problem);

/// u_h at parametric point uv of analysis cell c of patch p (order 0, 1 or 2).
SolutionValue evaluate_solution(const PoissonSolution& sol, std::size_t p, int c, const Eigen::Vector2d& uv,
                                int order = 1);
/// u_h at parametric point uv of patch p (the cell located first).
SolutionValue evaluate_solution(const PoissonSolution& sol, std::size_t p, const Eigen::Vector2d& uv, int order = 0);
/// The same with patch p's space given (AnalysisSpace::patch_space: also for
/// a patch this process does not hold).
SolutionValue evaluate_solution(const PoissonSolution& sol, std::size_t p, const PatchSpace& space, int c,
                                const Eigen::Vector2d& uv, int order = 1);

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
PoissonErrors compute_errors(const PoissonSolution& sol, const PoissonProblem& problem,
                             const InteriorSystemSolver* distributed = nullptr);

/// The largest difference of u_h between the two sides of the interfaces,
/// sampled at 33 points per cut (0 without interfaces): round-off on a
/// conforming glued space. With `distributed` (collective then), each process
/// samples the interfaces of the patches of its block of cells.
double interface_jump(const PoissonSolution& sol, const InteriorSystemSolver* distributed = nullptr);

}  // namespace tspline
