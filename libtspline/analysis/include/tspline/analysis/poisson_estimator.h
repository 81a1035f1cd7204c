#pragma once
// Residual-based a posteriori estimator of the IGA Poisson solver (Brovka et al.
// 2014, Sect. 7.2) and the marking of cells for the adaptive loop.
//
// Estimator: eta_e^2 = int_{S(e)} h_e^2 (f + Laplace u_h)^2 dx (4x4 Gauss points per piece),
// h_e = physical cell diameter, taken as the longer of the two diagonals of the
// image of the cell's corners, |S(c00) - S(c11)| and |S(c10) - S(c01)|.
// Laplace u_h uses the physical Hessian (see physical_hessian()).

#include <vector>

#include "tspline/analysis/poisson_solver.h"

namespace tspline {

/// eta_e per analysis cell (not squared; global cell numbering of
/// AnalysisSpace, every patch). If eta_scale is given it receives per
/// cell h_e (||f||^2 + ||Laplace u_h||^2)^{1/2} over the cell's image: the size of
/// the two terms whose sum is the residual, to recognize a residual at round-off.
/// With `distributed`, as compute_errors: each process its share, every process gets all cells.
std::vector<double> estimate_cells(const PoissonSolution& sol, const PoissonProblem& problem,
                                   std::vector<double>* eta_scale = nullptr,
                                   const InteriorSystemSolver* distributed = nullptr);

/// An estimator below this fraction of its scale (see estimate_cells) is round-off:
/// the adaptive loop then refines nothing. (Discrete solutions measure ~1e-15.)
inline constexpr double kRoundoffResidual = 1e-10;

/// The cells to split for the marked cells of one patch's T-mesh: each marked
/// cell and every leaf at most as fine that touches it (edge or corner). Splitting a cell alone adds no
/// hierarchical B-spline: a level-(l+1) function needs 4x4 level-(l+1) cells, i.e.
/// 2x2 split level-l cells; the 3x3 patch around a marked cell adds nine.
std::vector<int> refinement_patch(const TMesh& mesh, const std::vector<int>& marked);

/// Cells with eta_e > gamma * max eta (none if max eta is 0). \throw InputError unless 0 <= gamma <= 1.
std::vector<int> mark_cells(const std::vector<double>& eta, double gamma);

}  // namespace tspline
