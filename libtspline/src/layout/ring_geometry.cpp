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
  const int i0 = column(lo.x()), i1 = column(hi.x()), j0 = row(lo.y()), j1 = row(hi.y());
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

int RingGeometry::column(double x) const { return std::clamp(static_cast<int>((x - lo_.x()) / cell_), 0, nx_ - 1); }

int RingGeometry::row(double y) const { return std::clamp(static_cast<int>((y - lo_.y()) / cell_), 0, ny_ - 1); }

bool RingGeometry::inside(const Eigen::Vector2d& p) const {
  // Crossings of the ray from p in +x with the edges of the cells in its row.
  // An edge is in every cell its box meets; its crossing is counted in the
  // cell that holds it (the crossing's x taken within the edge's box, so that
  // the edge is in that cell), once.
  const int j = row(p.y()), i0 = column(p.x());
  int count = 0;
  for (int i = i0; i < nx_; ++i)
    for (const int e : cells_[static_cast<std::size_t>(j) * nx_ + i]) {
      const Eigen::Vector2d &a = edges_[e].a, &b = edges_[e].b;
      if ((a.y() > p.y()) == (b.y() > p.y())) continue;
      const double x = std::clamp(a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x()), std::min(a.x(), b.x()),
                                  std::max(a.x(), b.x()));
      if (x > p.x() && column(x) == i) ++count;
    }
  return count % 2 == 1;
}

int RingGeometry::crossing(const Eigen::Vector2d& a, const Eigen::Vector2d& b, bool a_on_ring, bool b_on_ring,
                           double tol) const {
  // The lowest-numbered edge crossed. An edge in several cells of the box is
  // tested in the first of them only (row by row: the larger of the box's and
  // the edge's first row and column).
  const Eigen::Vector2d lo = a.cwiseMin(b), hi = a.cwiseMax(b);
  const int i0 = column(lo.x()), j0 = row(lo.y());
  int first = -1;
  for_cells(lo, hi, [&](const std::vector<int>& cell) {
    for (const int g : cell) {
      if (first >= 0 && g >= first) continue;
      const Edge& f = edges_[g];
      const Eigen::Vector2d flo = f.a.cwiseMin(f.b), fhi = f.a.cwiseMax(f.b);
      if (flo.x() > hi.x() || fhi.x() < lo.x() || flo.y() > hi.y() || fhi.y() < lo.y()) continue;  // boxes apart
      // Tested once: in the first cell of the box that the edge is in.
      const int fi = std::max(i0, column(flo.x())), fj = std::max(j0, row(flo.y()));
      if (&cell != &cells_[static_cast<std::size_t>(fj) * nx_ + fi]) continue;
      if (crosses_edge(a, b, f, a_on_ring, b_on_ring, tol)) first = g;
    }
  });
  return first;
}

bool RingGeometry::crosses_edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Edge& f, bool a_on_ring,
                                bool b_on_ring, double tol) const {
  if (!segments_intersect(a, b, f.a, f.b)) return false;
  const bool a_on = a_on_ring && segment_distance(a, f.a, f.b) <= tol;
  const bool b_on = b_on_ring && segment_distance(b, f.a, f.b) <= tol;
  if (a_on && b_on) return true;  // along the edge
  if (a_on != b_on) {
    // Allowed: the segment's end on this edge, the rest of it off the edge
    // and off its line (a cut that goes on along the edge's line makes a
    // flat patch corner there; the patch layout refuses it as a crossing).
    if (CGAL::orientation(cp(f.a), cp(f.b), cp(a_on ? b : a)) == CGAL::COLLINEAR) return true;
    const Eigen::Vector2d from = a_on ? Eigen::Vector2d(a + 1e-6 * (b - a)) : a;
    const Eigen::Vector2d to = b_on ? Eigen::Vector2d(b + 1e-6 * (a - b)) : b;
    return segments_intersect(from, to, f.a, f.b);
  }
  return true;
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
