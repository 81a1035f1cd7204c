#include "tspline/layout/ring_geometry.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tspline {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
K::Point_2 cp(const Eigen::Vector2d& p) { return {p.x(), p.y()}; }

}  // namespace

double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

bool segments_intersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                        const Eigen::Vector2d& d) {
  return CGAL::do_intersect(K::Segment_2(cp(a), cp(b)), K::Segment_2(cp(c), cp(d)));
}

RingGeometry::RingGeometry(std::vector<Edge> edges, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi)
    : edges_(std::move(edges)) {
  const double n = std::max(8.0, std::sqrt(static_cast<double>(edges_.size())));
  cell_ = std::max((hi - lo).maxCoeff() / n, 1e-300);
  lo_ = lo - Eigen::Vector2d::Constant(cell_);
  nx_ = static_cast<int>((hi.x() - lo_.x()) / cell_) + 2;
  ny_ = static_cast<int>((hi.y() - lo_.y()) / cell_) + 2;
  cells_.assign(static_cast<std::size_t>(nx_) * ny_, {});
  for (std::size_t e = 0; e < edges_.size(); ++e)
    for_cells(edges_[e].a.cwiseMin(edges_[e].b), edges_[e].a.cwiseMax(edges_[e].b),
              [&](const std::vector<int>& c) { const_cast<std::vector<int>&>(c).push_back(static_cast<int>(e)); });
}

RingGeometry RingGeometry::of_rings(const std::vector<RingCurve>& rings) {
  std::vector<Edge> edges;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t r = 0; r < rings.size(); ++r)
    for (std::size_t i = 0; i < rings[r].size(); ++i) {
      edges.push_back({rings[r].vertex(i), rings[r].vertex(i + 1), static_cast<int>(r), i});
      lo = lo.cwiseMin(rings[r].vertex(i)), hi = hi.cwiseMax(rings[r].vertex(i));
    }
  return RingGeometry(std::move(edges), lo, hi);
}

template <class F>
void RingGeometry::for_cells(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, F&& f) const {
  const int i0 = std::clamp(static_cast<int>((lo.x() - lo_.x()) / cell_), 0, nx_ - 1);
  const int i1 = std::clamp(static_cast<int>((hi.x() - lo_.x()) / cell_), 0, nx_ - 1);
  const int j0 = std::clamp(static_cast<int>((lo.y() - lo_.y()) / cell_), 0, ny_ - 1);
  const int j1 = std::clamp(static_cast<int>((hi.y() - lo_.y()) / cell_), 0, ny_ - 1);
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) f(cells_[static_cast<std::size_t>(j) * nx_ + i]);
}

std::vector<int> RingGeometry::near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
  std::vector<int> out;
  for_cells(lo, hi, [&](const std::vector<int>& c) { out.insert(out.end(), c.begin(), c.end()); });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

bool RingGeometry::inside(const Eigen::Vector2d& p) const {
  // Crossings of the ray from p in +x with the edges of the cells in its row.
  const int j = std::clamp(static_cast<int>((p.y() - lo_.y()) / cell_), 0, ny_ - 1);
  const int i0 = std::clamp(static_cast<int>((p.x() - lo_.x()) / cell_), 0, nx_ - 1);
  std::vector<int> row;
  for (int i = i0; i < nx_; ++i) {
    const std::vector<int>& c = cells_[static_cast<std::size_t>(j) * nx_ + i];
    row.insert(row.end(), c.begin(), c.end());
  }
  std::sort(row.begin(), row.end());
  row.erase(std::unique(row.begin(), row.end()), row.end());
  int count = 0;
  for (int e : row) {
      const Eigen::Vector2d &a = edges_[e].a, &b = edges_[e].b;
      if ((a.y() > p.y()) == (b.y() > p.y())) continue;
      const double x = a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (x > p.x()) ++count;
    }
  return count % 2 == 1;
}

int RingGeometry::crossing(const Eigen::Vector2d& a, const Eigen::Vector2d& b, bool a_on_ring, bool b_on_ring,
                           double tol) const {
  for (int g : near(a.cwiseMin(b), a.cwiseMax(b))) {
    const Edge& f = edges_[g];
    if (!segments_intersect(a, b, f.a, f.b)) continue;
    const bool a_on = a_on_ring && segment_distance(a, f.a, f.b) <= tol;
    const bool b_on = b_on_ring && segment_distance(b, f.a, f.b) <= tol;
    if (a_on && b_on) return g;  // along the edge
    if (a_on != b_on) {
      // Allowed: the segment's end on this edge, the rest of it off the edge
      // and off its line (a cut that goes on along the edge's line makes a
      // flat patch corner there; the patch layout refuses it as a crossing).
      if (CGAL::orientation(cp(f.a), cp(f.b), cp(a_on ? b : a)) == CGAL::COLLINEAR) return g;
      const Eigen::Vector2d from = a_on ? Eigen::Vector2d(a + 1e-6 * (b - a)) : a;
      const Eigen::Vector2d to = b_on ? Eigen::Vector2d(b + 1e-6 * (a - b)) : b;
      if (!segments_intersect(from, to, f.a, f.b)) continue;
    }
    return g;
  }
  return -1;
}

int RingGeometry::nearest(const Eigen::Vector2d& p) const {
  int best = -1;
  double d = std::numeric_limits<double>::infinity();
  for (double r = cell_;; r *= 2.0) {
    for (int e : near(p - Eigen::Vector2d::Constant(r), p + Eigen::Vector2d::Constant(r))) {
      const double de = segment_distance(p, edges_[e].a, edges_[e].b);
      if (de < d) d = de, best = e;
    }
    // Edges farther than r from p may lie outside the box; within r they do not.
    if (best >= 0 && d <= r) return best;
    if (r > 4.0 * cell_ * std::max(nx_, ny_)) return best;
  }
}

}  // namespace tspline
