#pragma once
// Simultaneous untangling and smoothing of a planar mesh, node by node
// (Brovka 2013 Sect. 4; Gargallo-Peiro Algorithm 2 in the plane): Gauss-Seidel
// sweeps over the free nodes; per node, delta from the submesh (Appendix B),
// Newton steps with Armijo backtracking and a safe gradient fallback.
//
// The problem is given as free nodes with their local triangles; the library
// knows nothing about where they come from (T-meshes, triangle meshes, ...).
#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "meshopt/local_objective.h"

namespace meshopt {

/// Free nodes and their local submeshes in compressed form:
/// node k = nodes[k] moves; its triangles are triangles[offsets[k] .. offsets[k+1]).
struct SmoothingProblem {
  std::vector<int> nodes;
  std::vector<std::size_t> offsets{0};
  std::vector<LocalTriangle> triangles;

  /// Appends a free node with its triangles.
  void add_node(int node, std::span<const LocalTriangle> node_triangles);
  std::size_t size() const { return nodes.size(); }
  std::span<const LocalTriangle> triangles_of(std::size_t k) const;
};

struct SmoothingOptions {
  int max_sweeps = 500;
  /// Stop when max over nodes of |move| / (local length) < tolerance in one sweep,
  /// where local length is the mean distance to the submesh's other nodes.
  double relative_displacement_tolerance = 1e-3;
  /// Newton iterations per node per visit.
  int newton_iterations_per_visit = 4;
  /// alpha of the delta rule (Gargallo-Peiro Eq. 37), in [1e-6, 1e-3] (accepted: (0, 1]).
  double alpha = 1e-3;
  /// Over-relaxation factor omega in [1, 2) applied to each node's move once its
  /// submesh is valid (nonlinear SOR); 1 is plain Gauss-Seidel.
  double over_relaxation = 1.0;
  /// Armijo sufficient-decrease constant and maximum number of halvings.
  double armijo_c = 1e-4;
  int max_backtracks = 40;
  /// Called after each sweep (may be empty): sweep index, max relative move, tangled nodes.
  std::function<void(int, double, std::size_t)> progress;
};

struct SmoothingReport {
  int sweeps = 0;
  bool converged = false;
  double last_max_relative_move = 0.0;
  std::size_t tangled_nodes_before = 0;  ///< free nodes whose submesh has some sigma <= 0
  std::size_t tangled_nodes_after = 0;
  std::size_t node_visits = 0;  ///< node optimizations over all sweeps (converged nodes are skipped)
  std::size_t newton_steps = 0;
  std::size_t gradient_fallbacks = 0;
};

/// Moves positions[problem.nodes[k]] in place. Nodes not listed are fixed.
/// \throw toolkit::InputError (a std::invalid_argument) for indices out of range or bad options.
SmoothingReport smooth(std::vector<Eigen::Vector2d>& positions, const SmoothingProblem& problem,
                       const SmoothingOptions& options = {});

/// A smooth() run between its parts (smooth_until): the sweeps made, the
/// nodes still active, the report so far. Default: not started.
struct SmoothingRun {
  bool started = false;
  bool finished = false;  ///< converged, or options.max_sweeps made
  std::vector<char> active;
  std::vector<std::vector<int>> dependents;
  SmoothingReport report;
};

/// smooth() in parts: sweeps until `sweeps` in all (at most options.max_sweeps)
/// or convergence, then returns the report so far (tangled_nodes_after: now).
/// Called again with the same positions, problem, options and run and a larger
/// limit, it goes on where it stopped: parts up to options.max_sweeps give
/// smooth()'s positions and report bit for bit. Lets a caller look at the
/// mesh after a few sweeps before it pays for the rest.
SmoothingReport smooth_until(std::vector<Eigen::Vector2d>& positions, const SmoothingProblem& problem,
                             const SmoothingOptions& options, int sweeps, SmoothingRun& run);

/// Optimizes a single free node (used by smooth(); exposed for tests and for
/// callers with their own sweep logic). Returns the new position. Counters, if given,
/// are incremented by the accepted Newton / gradient steps.
/// \throw toolkit::InputError (a std::invalid_argument) for bad options or triangle indices out of range.
Eigen::Vector2d optimize_node(const Eigen::Vector2d& start, std::span<const Eigen::Vector2d> positions,
                              std::span<const LocalTriangle> triangles, const SmoothingOptions& options,
                              std::size_t* newton_steps = nullptr, std::size_t* gradient_fallbacks = nullptr);

}  // namespace meshopt
