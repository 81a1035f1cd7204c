// Errors, residual estimator, marking, refinement and the adaptive loop of the
// IGA Poisson solver (see poisson.h).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "tspline/bezier_extraction.h"
#include "tspline/errors.h"
#include "tspline/map_quality.h"
#include "tspline/poisson.h"

namespace tspline {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

Eigen::Vector2d exact_gradient(const PoissonProblem& p, double x, double y) {
  if (p.exact_gradient) return p.exact_gradient(x, y);
  const double h = kGradientStep;
  return {(p.exact(x + h, y) - p.exact(x - h, y)) / (2 * h), (p.exact(x, y + h) - p.exact(x, y - h)) / (2 * h)};
}

}  // namespace

PoissonErrors compute_errors(const TSplineMap& map, const PoissonSolution& sol, const PoissonProblem& problem,
                             const InteriorSystemSolver* distributed) {
  if (!problem.exact) throw InputError("Poisson errors: no exact solution given");
  const TMesh& mesh = sol.space->mesh();
  std::vector<QuadraturePoint> qp;
  PoissonErrors e;
  double l2 = 0, h1 = 0, l2u = 0, h1u = 0;
  const int nc = static_cast<int>(mesh.num_cells());
  const auto [first, last] = distributed ? distributed->cell_share(nc) : std::pair<int, int>{0, nc};
  for (int c = first; c < last; ++c) {
    box_quadrature(mesh.cell_min(c), mesh.cell_max(c), 6, qp, map.basis(), sol.space->geometry_cell(c));
    for (const QuadraturePoint& q : qp) {
      const SolutionValue v = evaluate_solution(map, sol, c, q.uv, 1);
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

std::vector<double> estimate_cells(const TSplineMap& map, const PoissonSolution& sol, const PoissonProblem& problem,
                                   std::vector<double>* eta_scale, const InteriorSystemSolver* distributed) {
  const TMesh& mesh = sol.space->mesh();
  std::vector<QuadraturePoint> qp;
  std::vector<double> eta(mesh.num_cells(), 0.0);
  if (eta_scale) eta_scale->assign(mesh.num_cells(), 0.0);
  const int nc = static_cast<int>(mesh.num_cells());
  const auto [first, last] = distributed ? distributed->cell_share(nc) : std::pair<int, int>{0, nc};
  for (int c = first; c < last; ++c) {
    const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
    const int g = sol.space->geometry_cell(c);
    // h_e: the longer diagonal of the image of the cell's corners.
    const Eigen::Vector2d p00 = map.derivatives(lo, 0, g).x, p11 = map.derivatives(hi, 0, g).x;
    const Eigen::Vector2d p10 = map.derivatives({hi.x(), lo.y()}, 0, g).x;
    const Eigen::Vector2d p01 = map.derivatives({lo.x(), hi.y()}, 0, g).x;
    const double h = std::max((p11 - p00).norm(), (p01 - p10).norm());
    double s = 0, scale = 0;
    box_quadrature(lo, hi, 4, qp, map.basis(), g);
    for (const QuadraturePoint& q : qp) {
      const SolutionValue v = evaluate_solution(map, sol, c, q.uv, 2);
      const double w = q.weight * std::abs(v.det_j);
      const double fv = problem.f(v.x.x(), v.x.y()), lap = v.hessian.trace();
      const double r = fv + lap;
      s += w * r * r;
      scale += w * (fv * fv + lap * lap);
    }
    eta[c] = h * std::sqrt(s);
    if (eta_scale) (*eta_scale)[c] = h * std::sqrt(scale);
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

std::vector<PoissonStep> solve_adaptive(const TSplineMap& map, const PoissonProblem& problem,
                                        const AdaptiveSolveOptions& options, const PoissonStepCallback& callback) {
  if (options.steps < 1) throw InputError("Poisson: steps must be at least 1");
  if (!(options.gamma >= 0.0 && options.gamma <= 1.0))
    throw InputError("gamma must lie in [0, 1], got " + std::to_string(options.gamma));
  std::vector<PoissonStep> steps;
  TMesh mesh = map.mesh();
  for (int k = 0; k < options.steps; ++k) {
    const auto t0 = Clock::now();
    auto space = std::make_shared<const AnalysisSpace>(map, mesh);
    if (k > 0 && space->num_dofs() > options.max_dofs) break;
    const PoissonSolution sol = solve_poisson(map, space, problem, options.solver);
    PoissonStep st;
    st.step = k;
    st.dofs = space->num_dofs();
    st.cells = space->mesh().num_cells();
    st.solver = sol.solver;
    st.assembly_seconds = sol.assembly_seconds;
    if (problem.exact) {
      st.has_errors = true;
      st.errors = compute_errors(map, sol, problem, options.solver);
    }
    std::vector<double> scale;
    const std::vector<double> eta = estimate_cells(map, sol, problem, &scale, options.solver);
    double s = 0, s_scale = 0;
    for (std::size_t c = 0; c < eta.size(); ++c) {
      s += eta[c] * eta[c];
      s_scale += scale[c] * scale[c];
    }
    st.eta = std::sqrt(s);
    // The residual f + Laplace(u_h) is a difference of two terms of size ~scale:
    // below kRoundoffResidual * scale it is round-off (u_h solves the problem
    // exactly, e.g. a solution in the discrete space) and there is nothing to refine.
    st.eta_at_roundoff = st.eta <= kRoundoffResidual * std::sqrt(s_scale);
    std::vector<int> marked;
    if (options.refine == AdaptiveSolveOptions::Refine::Uniform) {
      marked.resize(eta.size());
      for (int c = 0; c < static_cast<int>(eta.size()); ++c) marked[c] = c;
    } else if (!st.eta_at_roundoff) {
      marked = mark_cells(eta, options.gamma);
      st.marked = marked.size();
      marked = refinement_patch(mesh, marked);
    }
    if (options.refine == AdaptiveSolveOptions::Refine::Uniform) st.marked = marked.size();
    st.refined = marked.size();
    st.seconds = seconds_since(t0);
    steps.push_back(st);
    if (callback) callback(st, sol, eta);
    if (k + 1 < options.steps) {
      if (marked.empty()) break;  // nothing to refine (estimator zero or at round-off)
      mesh = refine_cells(mesh, marked);
    }
  }
  return steps;
}

}  // namespace tspline
