// Node-by-node untangling and smoothing (Brovka 2013 Sect. 4; Gargallo-Peiro
// Algorithm 2 in the plane). Per visit: delta from the submesh's smallest sigma
// (Gargallo-Peiro Appendix B, corrected Eq. 38), then Newton steps with Armijo
// backtracking; delta is set to 0 as soon as the node's submesh is valid.
#include "meshopt/node_smoother.h"

#include <algorithm>
#include <Eigen/LU>  // determinant()
#include <cmath>
#include <string>

#include "meshopt/triangle_measure.h"
#include "newton_descent.h"
#include "toolkit/errors.h"

namespace meshopt {

void SmoothingProblem::add_node(int node, std::span<const LocalTriangle> node_triangles) {
  if (offsets.empty()) offsets.push_back(0);
  nodes.push_back(node);
  triangles.insert(triangles.end(), node_triangles.begin(), node_triangles.end());
  offsets.push_back(triangles.size());
}

std::span<const LocalTriangle> SmoothingProblem::triangles_of(std::size_t k) const {
  return std::span<const LocalTriangle>(triangles).subspan(offsets[k], offsets[k + 1] - offsets[k]);
}

namespace detail {

void validate_options(const SmoothingOptions& o) {
  auto bad = [](const char* what) { throw toolkit::InputError(std::string("meshopt::smooth: ") + what); };
  if (o.max_sweeps < 0) bad("max_sweeps must be >= 0");
  if (!(o.relative_displacement_tolerance >= 0.0) || !std::isfinite(o.relative_displacement_tolerance))
    bad("relative_displacement_tolerance must be finite and >= 0");
  if (o.newton_iterations_per_visit < 1) bad("newton_iterations_per_visit must be >= 1");
  if (!(o.alpha > 0.0 && o.alpha <= 1.0)) bad("alpha must be in (0, 1] (the paper uses [1e-6, 1e-3])");
  if (!(o.armijo_c > 0.0 && o.armijo_c < 1.0)) bad("armijo_c must be in (0, 1)");
  if (o.max_backtracks < 0) bad("max_backtracks must be >= 0");
  if (!(o.over_relaxation >= 1.0 && o.over_relaxation < 2.0)) bad("over_relaxation must be in [1, 2)");
}

}  // namespace detail

namespace {


void validate_triangles(std::span<const Eigen::Vector2d> positions, std::span<const LocalTriangle> tris,
                        long long node) {
  const auto n = static_cast<long long>(positions.size());
  for (const LocalTriangle& t : tris) {
    if (t.a < 0 || t.a >= n || t.b < 0 || t.b >= n)
      throw toolkit::InputError("meshopt: triangle vertex index out of range");
    if (t.a == node || t.b == node || t.a == t.b)
      throw toolkit::InputError("meshopt: local triangle repeats a vertex (or references the free node)");
    if (!std::isfinite(t.weight) || t.weight < 0.0 || !t.ideal_inv.allFinite())
      throw toolkit::InputError("meshopt: triangle weight must be finite and >= 0, ideal_inv finite");
    if (!positions[t.a].allFinite() || !positions[t.b].allFinite())
      throw toolkit::InputError("meshopt: non-finite node position");
  }
}

/// Mean distance from x to the submesh nodes (each triangle's a and b counted once per
/// triangle; in a closed star or a quad-cell submesh every node appears equally often).
double local_length(const Eigen::Vector2d& x, std::span<const Eigen::Vector2d> positions,
                    std::span<const LocalTriangle> tris) {
  if (tris.empty()) return 0.0;
  double sum = 0.0;
  for (const LocalTriangle& t : tris) sum += (positions[t.a] - x).norm() + (positions[t.b] - x).norm();
  return sum / (2.0 * static_cast<double>(tris.size()));
}

using detail::Counters;

// The triangle objective in the form newton_descent expects.
struct TriangleObjective {
  std::span<const Eigen::Vector2d> positions;
  std::span<const LocalTriangle> tris;
  double min_sigma(const Eigen::Vector2d& x) const { return meshopt::min_sigma(x, positions, tris); }
  double mean_abs_sigma(const Eigen::Vector2d& x) const {
    double s = 0.0;
    for (const LocalTriangle& t : tris)
      s += std::abs(weighted_jacobian(x, positions[t.a], positions[t.b], t.ideal_inv).determinant());
    return s / static_cast<double>(tris.size());
  }
  ObjectiveValue full(const Eigen::Vector2d& x, double delta) const {
    return local_objective(x, positions, tris, delta);
  }
  double value(const Eigen::Vector2d& x, double delta) const {
    return local_objective_value(x, positions, tris, delta);
  }
};

Eigen::Vector2d optimize_impl(const Eigen::Vector2d& start, std::span<const Eigen::Vector2d> positions,
                              std::span<const LocalTriangle> tris, const SmoothingOptions& opt, double L,
                              Counters& cnt) {
  if (tris.empty()) return start;
  return detail::newton_descent(start, TriangleObjective{positions, tris}, opt, L, cnt);
}

}  // namespace

Eigen::Vector2d optimize_node(const Eigen::Vector2d& start, std::span<const Eigen::Vector2d> positions,
                              std::span<const LocalTriangle> triangles, const SmoothingOptions& options,
                              std::size_t* newton_steps, std::size_t* gradient_fallbacks) {
  detail::validate_options(options);
  validate_triangles(positions, triangles, -1);
  Counters cnt;
  const Eigen::Vector2d x =
      optimize_impl(start, positions, triangles, options, local_length(start, positions, triangles), cnt);
  if (newton_steps) *newton_steps += cnt.newton;
  if (gradient_fallbacks) *gradient_fallbacks += cnt.gradient;
  return x;
}

namespace {

std::size_t count_tangled(const std::vector<Eigen::Vector2d>& positions, const SmoothingProblem& p) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const auto tris = p.triangles_of(k);
    if (!tris.empty() && !(min_sigma(positions[p.nodes[k]], positions, tris) > 0.0)) ++n;
  }
  return n;
}

void validate_problem(const std::vector<Eigen::Vector2d>& positions, const SmoothingProblem& p) {
  if (p.offsets.size() != p.nodes.size() + 1 || p.offsets.front() != 0 ||
      p.offsets.back() != p.triangles.size())
    throw toolkit::InputError("meshopt::smooth: offsets inconsistent with nodes/triangles");
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (p.offsets[k] > p.offsets[k + 1]) throw toolkit::InputError("meshopt::smooth: offsets not sorted");
    const int node = p.nodes[k];
    if (node < 0 || static_cast<std::size_t>(node) >= positions.size())
      throw toolkit::InputError("meshopt::smooth: free node index out of range");
    if (!positions[node].allFinite()) throw toolkit::InputError("meshopt::smooth: non-finite node position");
    validate_triangles(positions, p.triangles_of(k), node);
  }
}

}  // namespace

namespace {

// For every global node, the free nodes (indices into problem.nodes) whose
// submesh contains it, i.e. whose objective changes when it moves.
std::vector<std::vector<int>> build_dependents(std::size_t num_positions, const SmoothingProblem& p) {
  std::vector<std::vector<int>> dep(num_positions);
  for (std::size_t k = 0; k < p.size(); ++k) {
    for (const LocalTriangle& t : p.triangles_of(k)) {
      for (int v : {t.a, t.b}) {
        auto& d = dep[v];
        if (d.empty() || d.back() != static_cast<int>(k)) d.push_back(static_cast<int>(k));
      }
    }
  }
  for (auto& d : dep) {
    std::sort(d.begin(), d.end());
    d.erase(std::unique(d.begin(), d.end()), d.end());
  }
  return dep;
}

}  // namespace

SmoothingReport smooth(std::vector<Eigen::Vector2d>& positions, const SmoothingProblem& problem,
                       const SmoothingOptions& options) {
  SmoothingRun run;
  return smooth_until(positions, problem, options, options.max_sweeps, run);
}

SmoothingReport smooth_until(std::vector<Eigen::Vector2d>& positions, const SmoothingProblem& problem,
                             const SmoothingOptions& options, int sweeps, SmoothingRun& run) {
  SmoothingReport& rep = run.report;
  if (!run.started) {
    detail::validate_options(options);
    validate_problem(positions, problem);
    rep.tangled_nodes_before = count_tangled(positions, problem);
    // Active set: a node is visited again only if it, or a node of its submesh,
    // moved by more than the tolerance since its last visit. Converged parts of the
    // mesh then cost nothing, and the stopping rule (largest relative move below
    // the tolerance) is unchanged: a skipped node's objective has not changed
    // beyond the tolerance, so it would not move either.
    run.dependents = build_dependents(positions.size(), problem);
    run.active.assign(problem.size(), 1);
    run.started = true;
  }
  const std::span<const Eigen::Vector2d> pos(positions);
  Counters cnt;
  cnt.newton = rep.newton_steps;
  cnt.gradient = rep.gradient_fallbacks;
  const std::vector<std::vector<int>>& dependents = run.dependents;
  std::vector<char>& active = run.active;
  const int limit = std::min(sweeps, options.max_sweeps);
  for (int sweep = rep.sweeps; !run.finished && sweep < limit; ++sweep) {
    double max_move = 0.0;
    std::size_t visited = 0;
    for (std::size_t k = 0; k < problem.size(); ++k) {
      if (!active[k]) continue;
      active[k] = 0;
      ++visited;
      const auto tris = problem.triangles_of(k);
      Eigen::Vector2d& xk = positions[problem.nodes[k]];
      const double L = local_length(xk, pos, tris);
      Eigen::Vector2d xn = optimize_impl(xk, pos, tris, options, L, cnt);
      // Nonlinear successive over-relaxation: push past the local optimum to
      // speed up the smooth, domain-wide modes that plain Gauss-Seidel removes
      // slowly. Taken only if the submesh stays valid there (no new tangling).
      if (options.over_relaxation != 1.0) {
        const Eigen::Vector2d xr = xk + options.over_relaxation * (xn - xk);
        if (min_sigma(xn, pos, tris) > 0.0 && min_sigma(xr, pos, tris) > 0.0) xn = xr;
      }
      const double move = L > 0.0 ? (xn - xk).norm() / L : 0.0;
      max_move = std::max(max_move, move);
      xk = xn;
      if (move >= options.relative_displacement_tolerance) {
        active[k] = 1;
        for (int m : dependents[problem.nodes[k]]) active[m] = 1;
      }
    }
    rep.sweeps = sweep + 1;
    rep.last_max_relative_move = max_move;
    rep.node_visits += visited;
    if (options.progress) options.progress(sweep, max_move, count_tangled(positions, problem));
    if (max_move < options.relative_displacement_tolerance) {
      rep.converged = true;
      run.finished = true;
    }
  }
  if (rep.sweeps >= options.max_sweeps) run.finished = true;
  rep.tangled_nodes_after = count_tangled(positions, problem);
  rep.newton_steps = cnt.newton;
  rep.gradient_fallbacks = cnt.gradient;
  return rep;
}

}  // namespace meshopt
