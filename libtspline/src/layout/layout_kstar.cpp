#include "tspline/layout/layout_kstar.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace tspline {

meshopt::SmoothingReport smooth_layout_kstar(LayoutMesh& m, const LayoutRings& R) {
  std::vector<Eigen::Vector2d>& x = m.x;
  const std::vector<std::array<int, 4>>& quads = m.quads;
  const std::vector<int>& ring = m.ring;
  const std::vector<double>& arc = m.arc;
  const std::vector<RingCurve>& rings = R.curves;
  const std::size_t n_nodes = x.size();
  std::vector<std::vector<std::pair<int, int>>> around(x.size());  // (quad, corner)
  for (std::size_t q = 0; q < quads.size(); ++q)
    for (int j = 0; j < 4; ++j) around[quads[q][j]].push_back({static_cast<int>(q), j});
  meshopt::SmoothingProblem problem;
  std::vector<meshopt::LocalTriangle> tris;
  for (std::size_t n = 0; n < n_nodes; ++n) {
    if (ring[n] >= 0 || around[n].empty()) continue;
    const double theta = 2.0 * std::numbers::pi / static_cast<double>(around[n].size());
    const Eigen::Vector2d e1(1.0, 0.0), e2(std::cos(theta), std::sin(theta));
    auto ideal_inv = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      Eigen::Matrix2d W;
      W << a, b;
      return Eigen::Matrix2d(W.inverse());
    };
    tris.clear();
    for (const auto& [q, j] : around[n]) {
      const int n1 = quads[q][(j + 1) % 4], o = quads[q][(j + 2) % 4], n2 = quads[q][(j + 3) % 4];
      tris.push_back({n1, n2, ideal_inv(e1, e2), 1.0});
      tris.push_back({n1, o, ideal_inv(e1, e1 + e2), 1.0});
      tris.push_back({o, n2, ideal_inv(e1 + e2, e2), 1.0});
      // The cut n -> n1 (each cut of n is the edge to n1 of exactly one quad around n).
      if (ring[n1] < 0) continue;
      const RingCurve& rc = rings[ring[n1]];
      // (On small rings l is capped: the points b+- must stay near b, on its own side.)
      const double l = std::min(0.2 * (x[n1] - x[n]).norm(), 0.05 * rc.length());
      const double dir = ring[n1] == 0 ? 1.0 : -1.0;  // the domain lies left of the outer ring, right of holes
      const int plus = static_cast<int>(x.size()), minus = plus + 1;
      x.push_back(rc.point(arc[n1] + dir * l));
      x.push_back(rc.point(arc[n1] - dir * l));
      // Ideal: b = (0, 0), b+ = (0.2, 0), x = (0, 1), b- = (-0.2, 0).
      tris.push_back({n1, plus, ideal_inv({0.0, -1.0}, {0.2, -1.0}), 1.0});
      tris.push_back({minus, n1, ideal_inv({-0.2, -1.0}, {0.0, -1.0}), 1.0});
    }
    problem.add_node(static_cast<int>(n), tris);
  }
  meshopt::SmoothingOptions so;
  so.max_sweeps = 200;
  const std::vector<Eigen::Vector2d> before(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(n_nodes));
  const meshopt::SmoothingReport report = meshopt::smooth(x, problem, so);
  x.resize(n_nodes);  // the ring points b+-
  // The regularized objective of a tangled start can shrink quads to a point
  // (|S|^2 / h(sigma) -> 0 as a triangle collapses with delta > 0): where a
  // quad has lost more than 99 % of its shortest edge, its nodes go back.
  for (const auto& q : quads) {
    double now = std::numeric_limits<double>::infinity(), was = now;
    for (int j = 0; j < 4; ++j) {
      now = std::min(now, (x[q[j]] - x[q[(j + 1) % 4]]).norm());
      was = std::min(was, (before[q[j]] - before[q[(j + 1) % 4]]).norm());
    }
    if (now < 1e-2 * was)
      for (int j = 0; j < 4; ++j) x[q[j]] = before[q[j]];
  }
  return report;
}

}  // namespace tspline
