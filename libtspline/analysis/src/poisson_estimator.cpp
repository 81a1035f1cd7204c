// Errors, interface jumps, residual estimator and marking of the IGA Poisson
// solver (see poisson_solver.h, poisson_estimator.h).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <span>
#include <stdexcept>
#include <vector>

#include "tspline/boundary/border_knots.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/errors.h"
#include "tspline/validity/map_quality.h"
#include "tspline/analysis/poisson.h"
#include "cell_tabulation.h"

namespace tspline {

namespace {

Eigen::Vector2d exact_gradient(const PoissonProblem& p, double x, double y) {
  if (p.exact_gradient) return p.exact_gradient(x, y);
  const double h = kGradientStep;
  return {(p.exact(x + h, y) - p.exact(x - h, y)) / (2 * h), (p.exact(x, y + h) - p.exact(x, y - h)) / (2 * h)};
}

/// This process's share of the cells: all of them, or the distributed solver's.
std::pair<int, int> cell_share(const AnalysisSpace& space, const InteriorSystemSolver* distributed) {
  const int nc = static_cast<int>(space.num_cells());
  return distributed ? distributed->cell_share(nc) : std::pair<int, int>{0, nc};
}

/// u_h and the map at the quadrature points of one analysis cell, from
/// tabulated univariate factors (cell_tabulation.h): the same values as
/// evaluate_solution() (up to the order of the additions), without evaluating
/// both bases at every point.
class CellEvaluator {
 public:
  explicit CellEvaluator(const PoissonSolution& sol) : sol_(sol) {}

  /// Tabulates global cell gc at n x n Gauss points per piece (box_quadrature),
  /// derivatives up to `order` (1 or 2); returns the points.
  const std::vector<QuadraturePoint>& set_cell(std::size_t gc, int n, int order) {
    order_ = order;
    const auto [p, c] = sol_.space->cell(gc);
    const PatchSpace& sp = sol_.space->patch(p);
    const TSplineMap& map = sol_.space->map(p);
    box_quadrature(sp.mesh().cell_min(c), sp.mesh().cell_max(c), n, qp_, map.basis(), sp.geometry_cell(c));
    cell_.set(map, sp, c, qp_, order);
    const std::span<const int> dofs = sol_.space->dofs(p);
    coef_.resize(cell_.ids.size());
    for (std::size_t k = 0; k < cell_.ids.size(); ++k) coef_[k] = sol_.coefficients[dofs[cell_.ids[k]]];
    return qp_;
  }

  /// evaluate_solution(sol, p, c, qp[q].uv, order) of the current cell.
  SolutionValue at(std::size_t q) const {
    const bool d2 = order_ >= 2;
    const MapDerivatives d = cell_.geometry(q);
    // u_h = sum c_a X_a(x) Y_a(y) (hierarchical B-splines are not normalized).
    SolutionValue out;
    out.x = d.x;
    out.det_j = d.J.determinant();
    Eigen::Vector2d g_xi = Eigen::Vector2d::Zero();
    Eigen::Matrix2d h_xi = Eigen::Matrix2d::Zero();
    for (std::size_t k = 0; k < coef_.size(); ++k) {
      const detail::Factor &a = cell_.x(q, k), &b = cell_.y(q, k);
      const double ca = coef_[k];
      out.u += ca * a.v * b.v;
      g_xi += ca * Eigen::Vector2d(a.d * b.v, a.v * b.d);
      if (d2) {
        h_xi(0, 0) += ca * a.dd * b.v;
        h_xi(0, 1) += ca * a.d * b.d;
        h_xi(1, 1) += ca * a.v * b.dd;
      }
    }
    h_xi(1, 0) = h_xi(0, 1);
    out.grad = d.J.transpose().partialPivLu().solve(g_xi);
    if (d2) out.hessian = physical_hessian(out.grad, h_xi, d);
    return out;
  }

 private:
  const PoissonSolution& sol_;
  int order_ = 1;
  std::vector<QuadraturePoint> qp_;
  detail::CellTabulation cell_;
  std::vector<double> coef_;
};

}  // namespace

PoissonErrors compute_errors(const PoissonSolution& sol, const PoissonProblem& problem,
                             const InteriorSystemSolver* distributed) {
  if (!problem.exact) throw InputError("Poisson errors: no exact solution given");
  PoissonErrors e;
  double l2 = 0, h1 = 0, l2u = 0, h1u = 0;
  const auto [first, last] = cell_share(*sol.space, distributed);
  CellEvaluator cell(sol);
  for (int gc = first; gc < last; ++gc) {
    const std::vector<QuadraturePoint>& qp = cell.set_cell(static_cast<std::size_t>(gc), 6, 1);
    for (std::size_t iq = 0; iq < qp.size(); ++iq) {
      const QuadraturePoint& q = qp[iq];
      const SolutionValue v = cell.at(iq);
      const double w = q.weight * std::abs(v.det_j);
      const double ue = problem.exact(v.x.x(), v.x.y());
      const Eigen::Vector2d ge = exact_gradient(problem, v.x.x(), v.x.y());
      l2 += w * (ue - v.u) * (ue - v.u);
      h1 += w * (ge - v.grad).squaredNorm();
      l2u += w * ue * ue;
      h1u += w * ge.squaredNorm();
      e.max_abs_at_qp = std::max(e.max_abs_at_qp, std::abs(ue - v.u));
    }
  }
  if (distributed) {  // the integrals are sums over the cells
    std::array<double, 4> sums{l2, h1, l2u, h1u};
    distributed->sum_over_processes(sums);
    l2 = sums[0];
    h1 = sums[1];
    l2u = sums[2];
    h1u = sums[3];
    distributed->max_over_processes({&e.max_abs_at_qp, 1});
  }
  e.l2 = std::sqrt(l2);
  e.h1 = std::sqrt(h1);
  e.l2_exact = std::sqrt(l2u);
  e.h1_exact = std::sqrt(h1u);
  return e;
}

double interface_jump(const PoissonSolution& sol, const InteriorSystemSolver* distributed) {
  const AnalysisSpace& space = *sol.space;
  // With several processes: the interfaces of the patches of this process's
  // block (it holds their neighbours too), the maximum taken over the processes.
  std::vector<char> mine(space.num_patches(), 1);
  if (distributed) {
    const auto [first, last] = distributed->cell_share(static_cast<int>(space.num_cells()));
    for (std::size_t p = 0; p < mine.size(); ++p)
      mine[p] = static_cast<int>(space.cell_offset(p)) < last && first < static_cast<int>(space.cell_offset(p + 1));
  }
  double jump = 0.0;
  for (const Interface& f : space.geometry().interfaces)
    for (int k = 0; k <= 32 && mine[f.patch_a]; ++k) {
      const double t = k / 32.0;
      const double ua = evaluate_solution(sol, f.patch_a, side_point_uv(f.side_a, t), 0).u;
      const double ub = evaluate_solution(sol, f.patch_b, side_point_uv(f.side_b, reversed_param(t)), 0).u;
      jump = std::max(jump, std::abs(ua - ub));
    }
  if (distributed) distributed->max_over_processes({&jump, 1});
  return jump;
}

std::vector<double> estimate_cells(const PoissonSolution& sol, const PoissonProblem& problem,
                                   std::vector<double>* eta_scale, const InteriorSystemSolver* distributed) {
  const AnalysisSpace& space = *sol.space;
  std::vector<double> eta(space.num_cells(), 0.0);
  if (eta_scale) eta_scale->assign(space.num_cells(), 0.0);
  const auto [first, last] = cell_share(space, distributed);
  CellEvaluator cell(sol);
  for (int gc = first; gc < last; ++gc) {
    const auto [p, c] = space.cell(static_cast<std::size_t>(gc));
    const TMesh& mesh = space.patch(p).mesh();
    const TSplineMap& map = space.map(p);
    const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
    const int g = space.patch(p).geometry_cell(c);
    // h_e: the longer diagonal of the image of the cell's corners.
    const Eigen::Vector2d p00 = map.derivatives(lo, 0, g).x, p11 = map.derivatives(hi, 0, g).x;
    const Eigen::Vector2d p10 = map.derivatives({hi.x(), lo.y()}, 0, g).x;
    const Eigen::Vector2d p01 = map.derivatives({lo.x(), hi.y()}, 0, g).x;
    const double h = std::max((p11 - p00).norm(), (p01 - p10).norm());
    double s = 0, scale = 0;
    const std::vector<QuadraturePoint>& qp = cell.set_cell(static_cast<std::size_t>(gc), 4, 2);
    for (std::size_t iq = 0; iq < qp.size(); ++iq) {
      const QuadraturePoint& q = qp[iq];
      const SolutionValue v = cell.at(iq);
      const double w = q.weight * std::abs(v.det_j);
      const double fv = problem.f(v.x.x(), v.x.y()), lap = v.hessian.trace();
      const double r = fv + lap;
      s += w * r * r;
      scale += w * (fv * fv + lap * lap);
    }
    eta[gc] = h * std::sqrt(s);
    if (eta_scale) (*eta_scale)[gc] = h * std::sqrt(scale);
  }
  if (distributed) {  // every process gets every cell's value (the others' are 0 here)
    distributed->sum_over_processes(eta);
    if (eta_scale) distributed->sum_over_processes(*eta_scale);
  }
  return eta;
}

std::vector<int> refinement_patch(const TMesh& mesh, const std::vector<int>& marked) {
  std::vector<char> take(mesh.num_cells(), 0);
  for (int c : marked) {
    take[c] = 1;
    const QuadNode& q = mesh.node(mesh.cell_node(c));
    const IPoint lo = TMesh::node_min(q), hi = TMesh::node_max(q);
    // Sample just outside the midpoints of the edges and the corners (doubled
    // integer coordinates): a neighbour at least as large as c is hit by one of
    // these samples; smaller neighbours are skipped.
    const std::int64_t xs[3] = {2 * lo.x - 1, lo.x + hi.x, 2 * hi.x + 1};
    const std::int64_t ys[3] = {2 * lo.y - 1, lo.y + hi.y, 2 * hi.y + 1};
    for (std::int64_t px : xs)
      for (std::int64_t py : ys) {
        const int n = mesh.leaf_at_doubled(px, py);
        if (n < 0) continue;  // outside [0,1]^2
        const int nc = mesh.cell_of_node(n);
        if (mesh.cell_level(nc) <= q.level) take[nc] = 1;
      }
  }
  std::vector<int> out;
  for (int c = 0; c < static_cast<int>(take.size()); ++c)
    if (take[c]) out.push_back(c);
  return out;
}

std::vector<int> mark_cells(const std::vector<double>& eta, double gamma) {
  if (!(gamma >= 0.0 && gamma <= 1.0)) throw InputError("gamma must lie in [0, 1], got " + std::to_string(gamma));
  std::vector<int> marked;
  if (eta.empty()) return marked;
  const double m = *std::max_element(eta.begin(), eta.end());
  if (!(m > 0.0)) return marked;
  for (int c = 0; c < static_cast<int>(eta.size()); ++c)
    if (eta[c] > gamma * m) marked.push_back(c);
  return marked;
}

}  // namespace tspline
