#include "tspline/boundary/border_knots.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "tspline/errors.h"

namespace tspline {
namespace {

// Integer position of chord parameter t on `side` (boundary_map.h orientation).
IPoint side_point(Side side, std::int64_t k) {
  const std::int64_t R = TMesh::kRoot;
  switch (side) {
    case Side::Bottom: return {k, 0};
    case Side::Right: return {R, k};
    case Side::Top: return {R - k, R};
    case Side::Left: return {0, R - k};
  }
  return {0, 0};
}

// Doubled coordinates of a point just inside [0,1]^2 next to border point p,
// towards increasing t (never on a cell line: odd in both coordinates).
std::pair<std::int64_t, std::int64_t> inside_after(Side side, const IPoint& p) {
  const std::int64_t R2 = 2 * TMesh::kRoot;
  switch (side) {
    case Side::Bottom: return {2 * p.x + 1, 1};
    case Side::Right: return {R2 - 1, 2 * p.y + 1};
    case Side::Top: return {2 * p.x - 1, R2 - 1};
    case Side::Left: return {1, 2 * p.y - 1};
  }
  return {1, 1};
}

}  // namespace

std::vector<double> border_params(const TMesh& mesh, Side side) {
  std::vector<double> t;
  for (int v = 0; v < static_cast<int>(mesh.num_vertices()); ++v) {
    const IPoint& p = mesh.vertex_ipos(v);
    const std::int64_t R = TMesh::kRoot;
    std::int64_t k = -1;
    switch (side) {
      case Side::Bottom: k = p.y == 0 ? p.x : -1; break;
      case Side::Right: k = p.x == R ? p.y : -1; break;
      case Side::Top: k = p.y == R ? R - p.x : -1; break;
      case Side::Left: k = p.x == 0 ? R - p.y : -1; break;
    }
    if (k >= 0) t.push_back(static_cast<double>(k) / static_cast<double>(R));
  }
  std::sort(t.begin(), t.end());
  return t;
}

std::size_t refine_to_border_params(TMesh& mesh, const BorderParams& params, int max_level) {
  std::vector<std::pair<Side, std::int64_t>> wanted;
  for (int s = 0; s < 4; ++s) {
    for (double t : params[s]) {
      const double k = t * static_cast<double>(TMesh::kRoot);
      if (!(t >= 0.0 && t <= 1.0) || k != std::floor(k))
        throw InputError("border parameter " + std::to_string(t) + " is not a dyadic number in [0, 1]");
      if (t > 0.0 && t < 1.0) wanted.emplace_back(static_cast<Side>(s), static_cast<std::int64_t>(k));
    }
  }
  std::size_t splits = 0;
  if (!mesh.has_topology()) mesh.build_topology();
  for (bool again = !wanted.empty(); again;) {
    again = false;
    for (const auto& [side, k] : wanted) {
      const IPoint p = side_point(side, k);
      if (mesh.find_vertex(p) >= 0) continue;
      const auto [dx, dy] = inside_after(side, p);
      const int n = mesh.leaf_at_doubled(dx, dy);
      if (mesh.node(n).level >= max_level) continue;
      mesh.refine(n);
      ++splits;
      again = true;
      mesh.balance();
      mesh.build_topology();
    }
  }
  return splits;
}

}  // namespace tspline
