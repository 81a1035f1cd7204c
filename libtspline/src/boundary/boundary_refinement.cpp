#include "tspline/boundary/boundary_refinement.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "tspline/errors.h"

namespace tspline {

double boundary_edge_error(const BoundaryMap& boundary, Side side, double t0, double t1) {
  const auto [first, last] = boundary.vertices_between(side, t0, t1);
  if (first >= last) return 0.0;
  const Eigen::Vector2d a = boundary.point(side, t0);
  const Eigen::Vector2d b = boundary.point(side, t1);
  const Eigen::Vector2d ab = b - a;
  const auto& pts = boundary.chain_points(side);
  double worst = 0.0;
  for (std::size_t k = first; k < last; ++k) {
    const Eigen::Vector2d ap = pts[k] - a;
    worst = std::max(worst, 0.5 * std::abs(ab.x() * ap.y() - ab.y() * ap.x()));
  }
  return worst;
}

bool boundary_edge_params(const QuadNode& q, CellEdge edge, Side& side, double& t0, double& t1) {
  const IPoint lo = TMesh::node_min(q), hi = TMesh::node_max(q);
  const double R = static_cast<double>(TMesh::kRoot);
  // Integer differences are exact, and division by a power of two is exact.
  switch (edge) {
    case CellEdge::Bottom:
      if (lo.y != 0) return false;
      side = Side::Bottom, t0 = lo.x / R, t1 = hi.x / R;
      return true;
    case CellEdge::Right:
      if (hi.x != TMesh::kRoot) return false;
      side = Side::Right, t0 = lo.y / R, t1 = hi.y / R;
      return true;
    case CellEdge::Top:
      if (hi.y != TMesh::kRoot) return false;
      side = Side::Top, t0 = (TMesh::kRoot - hi.x) / R, t1 = (TMesh::kRoot - lo.x) / R;
      return true;
    case CellEdge::Left:
      if (lo.x != 0) return false;
      side = Side::Left, t0 = (TMesh::kRoot - hi.y) / R, t1 = (TMesh::kRoot - lo.y) / R;
      return true;
  }
  return false;
}

namespace {

// Largest error over the boundary edges of a node (0 if it has none).
double node_boundary_error(const QuadNode& q, const BoundaryMap& boundary) {
  double worst = 0.0;
  for (int e = 0; e < 4; ++e) {
    Side side;
    double t0, t1;
    if (boundary_edge_params(q, static_cast<CellEdge>(e), side, t0, t1))
      worst = std::max(worst, boundary_edge_error(boundary, side, t0, t1));
  }
  return worst;
}

bool touches_boundary(const QuadNode& q) {
  const IPoint lo = TMesh::node_min(q), hi = TMesh::node_max(q);
  return lo.x == 0 || lo.y == 0 || hi.x == TMesh::kRoot || hi.y == TMesh::kRoot;
}

}  // namespace

BoundaryRefinementReport refine_to_boundary(TMesh& mesh, const BoundaryMap& boundary,
                                            const BoundaryRefinementOptions& options) {
  if (!(options.tolerance_area > 0.0) || !std::isfinite(options.tolerance_area))
    throw InputError("boundary tolerance must be a positive number");
  if (options.max_level < 1 || options.max_level > TMesh::kMaxLevel)
    throw InputError("maximum refinement level must be in [1, " + std::to_string(TMesh::kMaxLevel) + "]");
  if (options.max_cells < 1) throw InputError("`max_cells` must be >= 1");
  BoundaryRefinementReport report;
  std::size_t leaves = 0;
  for (const QuadNode& q : mesh.nodes()) leaves += q.is_leaf();
  auto over_budget = [&] {
    std::ostringstream s;
    s << "the boundary needs more than " << options.max_cells << " cells (`max_cells`) to meet the tolerance "
      << options.tolerance_area << " (an area) at levels up to " << options.max_level
      << ": raise `max_cells`, `tolerance_absolute` or `tolerance_relative`, or simplify the polygon (long thin parts need the most cells)";
    return InputError(s.str());
  };
  for (;;) {
    ++report.passes;
    std::vector<int> work;
    for (int n = 0; n < static_cast<int>(mesh.nodes().size()); ++n)
      if (mesh.node(n).is_leaf() && touches_boundary(mesh.node(n))) work.push_back(n);
    while (!work.empty()) {
      const int n = work.back();
      work.pop_back();
      const QuadNode q = mesh.node(n);
      if (q.level >= options.max_level) continue;
      if (node_boundary_error(q, boundary) <= options.tolerance_area) continue;
      if (leaves + 3 > options.max_cells) throw over_budget();
      const int c = mesh.refine(n);
      leaves += 3;
      ++report.boundary_splits;
      for (int k = 0; k < 4; ++k)
        if (touches_boundary(mesh.node(c + k))) work.push_back(c + k);
    }
    const std::size_t splits = mesh.balance();
    report.balance_splits += splits;
    leaves += 3 * splits;
    if (leaves > options.max_cells) throw over_budget();
    if (splits == 0) break;
  }
  for (const QuadNode& q : mesh.nodes()) {
    if (!q.is_leaf() || !touches_boundary(q)) continue;
    const double err = node_boundary_error(q, boundary);
    report.max_error = std::max(report.max_error, err);
    if (err > options.tolerance_area) ++report.edges_over_tolerance;
  }
  mesh.build_topology();
  return report;
}

}  // namespace tspline
