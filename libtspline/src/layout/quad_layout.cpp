#include "tspline/layout/quad_layout.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <Eigen/LU>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "meshopt/node_smoother.h"
#include "tspline/errors.h"
#include "tspline/layout/quad_mesher.h"

namespace tspline {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

K::Point_2 cp(const Eigen::Vector2d& p) { return {p.x(), p.y()}; }

bool segments_intersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                        const Eigen::Vector2d& d) {
  return CGAL::do_intersect(K::Segment_2(cp(a), cp(b)), K::Segment_2(cp(c), cp(d)));
}

// Ring edges bucketed on a uniform grid, for segment and point queries.
class EdgeGrid {
 public:
  struct Edge {
    Eigen::Vector2d a, b;
    int ring;
    std::size_t index;  // edge index in the ring (from vertex index to index + 1)
  };
  EdgeGrid(std::vector<Edge> edges, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) : edges_(std::move(edges)) {
    const double n = std::max(8.0, std::sqrt(static_cast<double>(edges_.size())));
    cell_ = std::max((hi - lo).maxCoeff() / n, 1e-300);
    lo_ = lo - Eigen::Vector2d::Constant(cell_);
    nx_ = static_cast<int>((hi.x() - lo_.x()) / cell_) + 2;
    ny_ = static_cast<int>((hi.y() - lo_.y()) / cell_) + 2;
    cells_.assign(static_cast<std::size_t>(nx_) * ny_, {});
    for (std::size_t e = 0; e < edges_.size(); ++e)
      for_cells(edges_[e].a.cwiseMin(edges_[e].b), edges_[e].a.cwiseMax(edges_[e].b),
                [&](std::vector<int>& c) { c.push_back(static_cast<int>(e)); });
  }
  const Edge& edge(int e) const { return edges_[e]; }
  /// Edges whose cells meet the box [lo, hi], each once.
  std::vector<int> near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
    std::vector<int> out;
    for_cells(lo, hi, [&](const std::vector<int>& c) { out.insert(out.end(), c.begin(), c.end()); });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
  /// Crossings of the ray from p in +x with the edges (the parity says inside or not).
  int ray_crossings(const Eigen::Vector2d& p) const {
    const int j = std::clamp(static_cast<int>((p.y() - lo_.y()) / cell_), 0, ny_ - 1);
    const int i0 = std::clamp(static_cast<int>((p.x() - lo_.x()) / cell_), 0, nx_ - 1);
    std::set<int> seen;
    int count = 0;
    for (int i = i0; i < nx_; ++i)
      for (int e : cells_[static_cast<std::size_t>(j) * nx_ + i]) {
        if (!seen.insert(e).second) continue;
        const Eigen::Vector2d &a = edges_[e].a, &b = edges_[e].b;
        if ((a.y() > p.y()) == (b.y() > p.y())) continue;
        const double x = a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
        if (x > p.x()) ++count;
      }
    return count;
  }

 private:
  template <class F>
  void for_cells(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, F&& f) const {
    const int i0 = std::clamp(static_cast<int>((lo.x() - lo_.x()) / cell_), 0, nx_ - 1);
    const int i1 = std::clamp(static_cast<int>((hi.x() - lo_.x()) / cell_), 0, nx_ - 1);
    const int j0 = std::clamp(static_cast<int>((lo.y() - lo_.y()) / cell_), 0, ny_ - 1);
    const int j1 = std::clamp(static_cast<int>((hi.y() - lo_.y()) / cell_), 0, ny_ - 1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) f(const_cast<std::vector<int>&>(cells_[static_cast<std::size_t>(j) * nx_ + i]));
  }
  std::vector<Edge> edges_;
  std::vector<std::vector<int>> cells_;
  Eigen::Vector2d lo_;
  double cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
};

// The quads around each node (indices into quads).
std::vector<std::vector<int>> quads_around(std::size_t nodes, const std::vector<std::array<int, 4>>& quads) {
  std::vector<std::vector<int>> out(nodes);
  for (std::size_t q = 0; q < quads.size(); ++q)
    for (int j = 0; j < 4; ++j) out[quads[q][j]].push_back(static_cast<int>(q));
  return out;
}

// Use count of every edge of the quads (1: on a ring, 2: inner).
std::map<std::pair<int, int>, int> edge_uses(const std::vector<std::array<int, 4>>& quads) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& q : quads)
    for (int j = 0; j < 4; ++j) ++uses[{std::min(q[j], q[(j + 1) % 4]), std::max(q[j], q[(j + 1) % 4])}];
  return uses;
}

// Distance of p from the segment [a, b].
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// The piece (index into nodes) of ring arc length s.
std::size_t piece_of(const std::vector<double>& nodes, double s) {
  const auto it = std::upper_bound(nodes.begin(), nodes.end(), s);
  return it == nodes.begin() ? nodes.size() - 1 : static_cast<std::size_t>(it - nodes.begin()) - 1;
}

// A node more on piece k of a ring: its vertex farthest from the chord, or its middle.
void split_piece(const RingCurve& ring, std::vector<double>& nodes, std::size_t k) {
  const double L = ring.length();
  const double a = nodes[k], b = k + 1 < nodes.size() ? nodes[k + 1] : nodes.front() + L;
  const auto [dev, at] = ring.farthest_from_chord(a, b);
  double s = 0.5 * (a + b);
  if (at > 0.0 && dev > 1e-3 * (ring.point(b) - ring.point(a)).norm() && at - a > 0.1 * (b - a) && b - at > 0.1 * (b - a))
    s = at;
  nodes.push_back(std::fmod(s, L));
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
}

// Untangles and smooths the inner nodes of the quad mesh (libmeshopt, the
// weighted K* objective of Brovka Eqs. 3-5) with the ring nodes fixed. Per
// quad (x, n1, o, n2) around an inner node x of valence k, the three corner
// triangles that contain x, each with the ideal shape of the rhombus with
// angle 2 pi / k at x (a square where k = 4).
//
// And where a cut joins an inner node x to a ring node b: the two triangles
// (b, b+, x) and (b, x, b-), b+- the points of the ring at arc length
// +- l = |x - b| / 5 from b (the domain's side first), ideal with a right
// angle at b, so that cuts leave the coast at right angles on the scale of
// the patch's first cells (a corner angle theta bounds the patch map's
// scaled Jacobian by sin theta).
meshopt::SmoothingReport smooth_inner_nodes(std::vector<Eigen::Vector2d>& x, const std::vector<std::array<int, 4>>& quads,
                                            const std::vector<int>& ring, const std::vector<double>& arc,
                                            const std::vector<RingCurve>& rings) {
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

double corner_sj(const Eigen::Vector2d& p, const Eigen::Vector2d& next, const Eigen::Vector2d& prev) {
  const Eigen::Vector2d e1 = next - p, e2 = prev - p;
  const double l = e1.norm() * e2.norm();
  return l > 0.0 ? cross(e1, e2) / l : -1.0;
}

// Slides each ring node along its ring, between its neighbours on the ring,
// to the place where the worst corner of its quads is best (straight sides),
// the ring's sharp turns kept where they are: a node whose ring turns by more
// than 25 degrees within a fifth of its shorter piece stays (a tip, the head
// of an inlet: a patch corner belongs there). Golden-section search on the
// arc length; quads around a node stay valid (their worst corner never drops).
void slide_ring_nodes(std::vector<Eigen::Vector2d>& x, std::vector<double>& arc,
                      const std::vector<std::array<int, 4>>& quads, const std::vector<int>& ring,
                      const std::vector<RingCurve>& rings) {
  const std::size_t n_nodes = x.size();
  const std::vector<std::vector<int>> quads_of = quads_around(n_nodes, quads);
  // Ring neighbours: the other ends of the node's edges on the ring (edges of one quad).
  const std::map<std::pair<int, int>, int> count = edge_uses(quads);
  std::vector<std::vector<int>> ring_nbr(n_nodes);
  for (const auto& [e, c] : count)
    if (c == 1) ring_nbr[e.first].push_back(e.second), ring_nbr[e.second].push_back(e.first);
  auto worst = [&](int n) {
    double m = 1.0;
    for (int q : quads_of[n])
      for (int j = 0; j < 4; ++j)
        m = std::min(m, corner_sj(x[quads[q][j]], x[quads[q][(j + 1) % 4]], x[quads[q][(j + 3) % 4]]));
    return m;
  };
  for (std::size_t n = 0; n < n_nodes; ++n) {
    if (ring[n] < 0 || ring_nbr[n].size() != 2) continue;
    const RingCurve& rc = rings[ring[n]];
    const double L = rc.length();
    // Neighbour arc lengths unwrapped around arc[n].
    double lo = arc[ring_nbr[n][0]], hi = arc[ring_nbr[n][1]];
    auto unwrap = [&](double a) {
      while (a - arc[n] > 0.5 * L) a -= L;
      while (arc[n] - a > 0.5 * L) a += L;
      return a;
    };
    lo = unwrap(lo), hi = unwrap(hi);
    if (lo > hi) std::swap(lo, hi);
    if (!(lo < arc[n] && arc[n] < hi)) continue;
    const double gap = std::min(arc[n] - lo, hi - arc[n]);
    const double l = 0.2 * gap;
    const Eigen::Vector2d t1 = rc.point(arc[n] + l) - x[n], t0 = x[n] - rc.point(arc[n] - l);
    const double turn = std::abs(std::atan2(cross(t0, t1), t0.dot(t1)));
    if (turn > 25.0 * std::numbers::pi / 180.0) continue;
    // Never across a corner of the ring (a turn of more than 45 degrees on the scale l):
    // the side would have a kink inside it.
    auto turn_at = [&](double sv) {
      const Eigen::Vector2d p = rc.point(sv), u = rc.point(sv + l) - p, w = p - rc.point(sv - l);
      return std::abs(std::atan2(cross(w, u), w.dot(u)));
    };
    for (std::size_t i = 0; i < rc.size(); ++i) {
      double si = rc.arc(i);
      while (si - arc[n] > 0.5 * L) si -= L;
      while (arc[n] - si > 0.5 * L) si += L;
      if (!(lo < si && si < hi) || si == arc[n] || turn_at(si) <= 0.25 * std::numbers::pi) continue;
      if (si < arc[n]) lo = std::max(lo, si);
      else hi = std::min(hi, si);
    }
    const double a0 = lo + 0.2 * (arc[n] - lo), b0 = hi - 0.2 * (hi - arc[n]);
    const double start = arc[n];
    const double before = worst(static_cast<int>(n));
    auto f = [&](double sv) {
      x[n] = rc.point(sv);
      return worst(static_cast<int>(n));
    };
    double a = a0, b = b0;
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double c = b - g * (b - a), d = a + g * (b - a);
    double fc = f(c), fd = f(d);
    for (int it = 0; it < 20; ++it) {
      if (fc > fd) b = d, d = c, fd = fc, c = b - g * (b - a), fc = f(c);
      else a = c, c = d, fc = fd, d = a + g * (b - a), fd = f(d);
    }
    const double best = fc > fd ? c : d;
    if (std::max(fc, fd) > before) {
      arc[n] = rc.snap_to_vertex(std::fmod(best + L, L), 1e-3 * (hi - lo));
      x[n] = rc.point(arc[n]);
    } else {
      x[n] = rc.point(start);
    }
  }
}

// Whether ring node v, as the corner of a single quad (v, a, ., b), would be
// a flat (inner angle above 150 degrees) or reflex patch corner: between the
// chords to a and b, or between the ring's own edges at v.
bool flat_single_corner(const std::vector<Eigen::Vector2d>& x, const std::vector<int>& ring,
                        const std::vector<double>& arc, const std::vector<RingCurve>& rings, int v, int a, int b) {
  auto flat_or_reflex = [](const Eigen::Vector2d& p, const Eigen::Vector2d& next, const Eigen::Vector2d& prev) {
    const double sv = corner_sj(p, next, prev);
    return sv < 0.0 || (sv <= 0.5 && (next - p).dot(prev - p) < 0.0);
  };
  const RingCurve& rc = rings[ring[v]];
  const double delta = 1e-6 * std::min((x[a] - x[v]).norm(), (x[b] - x[v]).norm());
  const double dir = ring[v] == 0 ? 1.0 : -1.0;  // the domain lies left of the outer ring, right of holes
  return flat_or_reflex(x[v], x[a], x[b]) ||
         flat_or_reflex(x[v], rc.point(arc[v] + dir * delta), rc.point(arc[v] - dir * delta));
}

// A flat single-quad ring corner moved along its ring by edge rotations until
// it lands where a patch corner is fine (a convex turn of the ring, or a node
// with more quads): the quad (v, a, o, b) and its neighbour across (a, o),
// (o, a, p, r), become (v, a, p, r) and (v, r, o, b), so that v has two quads
// and a one fewer (and o, an inner node, one fewer: never below three); then
// the same from a, up to 8 steps, in whichever direction ends first. Returns
// the corners moved; the others are left to pillowing.
std::size_t walk_flat_ring_corners(std::vector<std::array<int, 4>>& quads, const std::vector<Eigen::Vector2d>& x,
                                   const std::vector<int>& ring, const std::vector<double>& arc,
                                   const std::vector<RingCurve>& rings) {
  std::size_t moved = 0;
  for (std::size_t v0 = 0; v0 < x.size(); ++v0) {
    if (ring[v0] < 0) continue;
    std::vector<std::vector<int>> quads_of = quads_around(x.size(), quads);
    if (quads_of[v0].size() != 1) continue;
    {
      std::array<int, 4> q = quads[quads_of[v0][0]];
      while (q[0] != static_cast<int>(v0)) std::rotate(q.begin(), q.begin() + 1, q.end());
      if (!flat_single_corner(x, ring, arc, rings, static_cast<int>(v0), q[1], q[3])) continue;
    }
    std::vector<std::array<int, 4>> best;
    int best_steps = 1 << 30;
    for (const bool forward : {true, false}) {
      std::vector<std::array<int, 4>> trial = quads;
      int v = static_cast<int>(v0), steps = 0;
      bool ok = false;
      for (; steps < 8; ++steps) {
        const std::vector<std::vector<int>> around = quads_around(x.size(), trial);
        if (around[v].size() != 1) break;
        const int qi = around[v][0];
        std::array<int, 4> q = trial[qi];
        while (q[0] != v) std::rotate(q.begin(), q.begin() + 1, q.end());
        // Mirror the quad for the other direction: (v, b, o, a) walks towards b.
        const int a = forward ? q[1] : q[3], o = q[2], b = forward ? q[3] : q[1];
        if (ring[a] < 0 || ring[o] >= 0 || around[o].size() < 4) break;
        // The neighbour across (a, o).
        int ni = -1, nj = -1;
        for (int cand : around[a])
          for (int j = 0; j < 4; ++j)
            if (cand != qi && ((trial[cand][j] == o && trial[cand][(j + 1) % 4] == a) ||
                               (trial[cand][j] == a && trial[cand][(j + 1) % 4] == o)))
              ni = cand, nj = j;
        if (ni < 0) break;
        std::array<int, 4> n = trial[ni];
        while (n[0] != (forward ? o : a)) std::rotate(n.begin(), n.begin() + 1, n.end());
        // forward: n = (o, a, p, r); backward (mirrored): n = (a, o, r, p).
        const int p = forward ? n[2] : n[3], r = forward ? n[3] : n[2];
        if (p == v || r == v) break;
        if (forward) {
          trial[qi] = {v, a, p, r};
          trial[ni] = {v, r, o, b};
        } else {
          trial[qi] = {v, r, p, a};
          trial[ni] = {v, b, o, r};
        }
        (void)nj;
        // Where the corner is now: a, with one quad fewer.
        const std::vector<std::vector<int>> after = quads_around(x.size(), trial);
        if (after[a].size() >= 2) {
          ok = true;
          ++steps;
          break;
        }
        std::array<int, 4> qa = trial[after[a][0]];
        while (qa[0] != a) std::rotate(qa.begin(), qa.begin() + 1, qa.end());
        if (!flat_single_corner(x, ring, arc, rings, a, qa[1], qa[3])) {
          ok = true;
          ++steps;
          break;
        }
        v = a;
      }
      if (ok && steps < best_steps) best = trial, best_steps = steps;
    }
    if (best_steps < (1 << 30)) {
      quads = std::move(best);
      ++moved;
    }
  }
  return moved;
}

// A ring node that is the corner of one quad only, where the ring is nearly
// straight (inner angle above 150 degrees, between the chords to the quad's
// neighbours or between the ring's own edges at the node) or reflex, would be
// a patch corner of about 180 degrees or more: no map is valid there (det J at
// a corner of the square is the cross product of the two boundary tangents),
// and no local edge rotation removes it (it moves to a neighbour). Such a ring
// is pillowed: every node of it moves inside, a copy takes its place on the
// ring, and each quad edge along the ring gets a new quad between the two
// (a conforming layer; every ring node then has two quads). The inner nodes
// are smoothed afterwards. Returns the rings pillowed.
std::size_t pillow_flat_rings(std::vector<std::array<int, 4>>& quads, std::vector<Eigen::Vector2d>& x,
                              std::vector<int>& ring, std::vector<double>& arc, const std::vector<RingCurve>& rings) {
  const std::vector<std::vector<int>> quads_of = quads_around(x.size(), quads);
  auto flat_or_reflex = [](const Eigen::Vector2d& p, const Eigen::Vector2d& next, const Eigen::Vector2d& prev) {
    const double sv = corner_sj(p, next, prev);
    return sv < 0.0 || (sv <= 0.5 && (next - p).dot(prev - p) < 0.0);
  };
  std::vector<char> pillow(rings.size(), 0);
  for (std::size_t v = 0; v < x.size(); ++v) {
    if (ring[v] < 0 || quads_of[v].size() != 1) continue;
    std::array<int, 4> q = quads[quads_of[v][0]];
    while (q[0] != static_cast<int>(v)) std::rotate(q.begin(), q.begin() + 1, q.end());
    const int a = q[1], b = q[3];
    const RingCurve& rc = rings[ring[v]];
    const double delta = 1e-6 * std::min((x[a] - x[v]).norm(), (x[b] - x[v]).norm());
    const double dir = ring[v] == 0 ? 1.0 : -1.0;  // the domain lies left of the outer ring, right of holes
    if (flat_or_reflex(x[v], x[a], x[b]) ||
        flat_or_reflex(x[v], rc.point(arc[v] + dir * delta), rc.point(arc[v] - dir * delta)))
      pillow[ring[v]] = 1;
  }
  std::size_t count = 0;
  for (std::size_t r = 0; r < rings.size(); ++r) count += pillow[r];
  if (count == 0) return 0;
  // Edges along the ring, as directed in their quad.
  std::map<std::pair<int, int>, int> uses = edge_uses(quads);
  std::vector<std::pair<int, int>> along;
  for (const auto& q : quads)
    for (int j = 0; j < 4; ++j) {
      const int v = q[j], w = q[(j + 1) % 4];
      if (uses[{std::min(v, w), std::max(v, w)}] == 1 && ring[v] >= 0 && pillow[ring[v]]) along.push_back({v, w});
    }
  const std::size_t n0 = x.size();
  std::vector<int> copy(n0, -1);
  for (std::size_t v = 0; v < n0; ++v) {
    if (ring[v] < 0 || !pillow[ring[v]]) continue;
    copy[v] = static_cast<int>(x.size());
    x.push_back(x[v]);
    ring.push_back(ring[v]);
    arc.push_back(arc[v]);
  }
  // The old ring nodes move a third of the way towards the mean of their other quad corners.
  for (std::size_t v = 0; v < n0; ++v) {
    if (copy[v] < 0) continue;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    int k = 0;
    for (int q : quads_of[v])
      for (int j = 0; j < 4; ++j)
        if (quads[q][j] != static_cast<int>(v)) mean += x[quads[q][j]], ++k;
    if (k > 0) x[v] += (1.0 / 3.0) * (mean / k - x[v]);
    ring[v] = -1;
  }
  for (const auto& [v, w] : along) quads.push_back({w, v, copy[v], copy[w]});
  return count;
}

// A ring node at a sharp tip of its ring (inner angle below 60 degrees next to
// the node) with one cut: the cut would split the tip into two needle corners.
// Its two quads (b, r1, y1, x) and (b, x, y2, r2) form a hexagon, split again
// by a diagonal away from b, (r1, y1, x, y2) + (y2, r2, b, r1) or
// (b, r1, y1, r2) + (y1, x, y2, r2), the one with the better worst corner, so
// that b is the corner of one quad (an edge rotation; x keeps valence >= 3).
std::size_t free_sharp_tips(std::vector<std::array<int, 4>>& quads, const std::vector<Eigen::Vector2d>& x,
                            const std::vector<int>& ring, const std::vector<double>& arc,
                            const std::vector<RingCurve>& rings) {
  std::size_t changed = 0;
  std::vector<std::vector<int>> quads_of = quads_around(x.size(), quads);
  auto rebuild = [&] { quads_of = quads_around(x.size(), quads); };
  auto quad_sj = [&](const std::array<int, 4>& q) {
    double m = 1.0;
    for (int j = 0; j < 4; ++j) m = std::min(m, corner_sj(x[q[j]], x[q[(j + 1) % 4]], x[q[(j + 3) % 4]]));
    return m;
  };
  const double sharp = std::cos(60.0 * std::numbers::pi / 180.0);
  for (std::size_t b = 0; b < x.size(); ++b) {
    if (ring[b] < 0 || quads_of[b].size() != 2) continue;
    const RingCurve& rc = rings[ring[b]];
    const double dir = ring[b] == 0 ? 1.0 : -1.0;
    double near = 1e300;
    for (int q : quads_of[b])
      for (int j = 0; j < 4; ++j)
        if (quads[q][j] != static_cast<int>(b)) near = std::min(near, (x[quads[q][j]] - x[b]).norm());
    const double delta = 1e-6 * near;
    const Eigen::Vector2d ahead = rc.point(arc[b] + dir * delta) - x[b], behind = rc.point(arc[b] - dir * delta) - x[b];
    // Convex and sharp: cross(ahead, behind) > 0 and the angle below 60 degrees.
    if (!(cross(ahead, behind) > 0.0 && ahead.normalized().dot(behind.normalized()) > sharp)) continue;
    // The two quads, each rotated to start at b: (b, r1, y1, x) and (b, x, y2, r2).
    std::array<int, 4> qa = quads[quads_of[b][0]], qb = quads[quads_of[b][1]];
    while (qa[0] != static_cast<int>(b)) std::rotate(qa.begin(), qa.begin() + 1, qa.end());
    while (qb[0] != static_cast<int>(b)) std::rotate(qb.begin(), qb.begin() + 1, qb.end());
    int ia = quads_of[b][0], ib = quads_of[b][1];
    if (qa[3] != qb[1]) std::swap(qa, qb), std::swap(ia, ib);
    if (qa[3] != qb[1]) continue;  // not sharing the cut b-x
    const int r1 = qa[1], y1 = qa[2], xn = qa[3], y2 = qb[2], r2 = qb[3];

    if (ring[xn] >= 0 || quads_of[xn].size() < 4) continue;  // x would drop below valence 3
    const std::array<int, 4> A1 = {r1, y1, xn, y2}, B1 = {y2, r2, static_cast<int>(b), r1};
    const std::array<int, 4> A2 = {static_cast<int>(b), r1, y1, r2}, B2 = {y1, xn, y2, r2};
    const double m1 = std::min(quad_sj(A1), quad_sj(B1)), m2 = std::min(quad_sj(A2), quad_sj(B2));
    if (std::max(m1, m2) <= 0.0) continue;
    quads[ia] = m1 >= m2 ? A1 : A2;
    quads[ib] = m1 >= m2 ? B1 : B2;
    ++changed;
    rebuild();
  }
  return changed;
}

// The worst corners: each inner node where a corner of its quads is below 20
// or above 160 degrees moves, by a pattern search, to where the worst corner
// of its quads is best (max-min: the K* smoothing spreads the distortion, a
// patch map is bounded by its worst corner, SJ <= sin theta). At a ring node
// the corner is measured against the ring itself next to the node (the patch
// polygon's angle, at the vertex), not against the chord to the next ring node.
void improve_worst_corners(std::vector<Eigen::Vector2d>& x, const std::vector<std::array<int, 4>>& quads,
                           const std::vector<int>& ring, const std::vector<double>& arc,
                           const std::vector<RingCurve>& rings) {
  const std::size_t n_nodes = x.size();
  const std::vector<std::vector<int>> quads_of = quads_around(n_nodes, quads);
  std::map<std::pair<int, int>, int> uses = edge_uses(quads);
  auto on_ring_edge = [&](int a, int b) { return uses[{std::min(a, b), std::max(a, b)}] == 1; };
  // Corner j of quad q, the ring's own direction where the side runs along it.
  auto corner = [&](const std::array<int, 4>& q, int j) {
    const int v = q[j], next = q[(j + 1) % 4], prev = q[(j + 3) % 4];
    Eigen::Vector2d pn = x[next], pp = x[prev];
    if (ring[v] >= 0) {
      const RingCurve& rc = rings[ring[v]];
      const double dir = ring[v] == 0 ? 1.0 : -1.0;
      // At the vertex itself: the patch polygon's own corner there.
      if (on_ring_edge(v, next)) pn = rc.point(arc[v] + dir * 1e-6 * (x[next] - x[v]).norm());
      if (on_ring_edge(v, prev)) pp = rc.point(arc[v] - dir * 1e-6 * (x[prev] - x[v]).norm());
    }
    return corner_sj(x[v], pn, pp);
  };
  auto worst = [&](int n) {
    double m = 1.0;
    for (int q : quads_of[n])
      for (int j = 0; j < 4; ++j) m = std::min(m, corner(quads[q], j));
    return m;
  };
  const double bad = std::sin(20.0 * std::numbers::pi / 180.0);
  for (int pass = 0; pass < 3; ++pass)
    for (std::size_t n = 0; n < n_nodes; ++n) {
      if (ring[n] >= 0 || quads_of[n].empty()) continue;
      double best = worst(static_cast<int>(n));
      if (best >= bad) continue;
      double step = 1e300;
      for (int q : quads_of[n])
        for (int j = 0; j < 4; ++j) step = std::min(step, (x[quads[q][j]] - x[quads[q][(j + 1) % 4]]).norm());
      step *= 0.25;
      // No edge of the node shorter than a third of what it was (the angles alone
      // would let it run onto a neighbour).
      std::vector<std::pair<int, double>> edges;
      for (int q : quads_of[n])
        for (int j = 0; j < 4; ++j)
          if (quads[q][j] == static_cast<int>(n))
            for (const int o : {quads[q][(j + 1) % 4], quads[q][(j + 3) % 4]})
              edges.push_back({o, (x[o] - x[n]).norm() / 3.0});
      auto short_edge = [&]() {
        for (const auto& [o, min_len] : edges)
          if ((x[o] - x[n]).norm() < min_len) return true;
        return false;
      };
      for (int it = 0; it < 24 && step > 0.0; ++it) {
        bool moved = false;
        const Eigen::Vector2d start = x[n];
        for (int k = 0; k < 8; ++k) {
          const double a = k * std::numbers::pi / 4.0;
          x[n] = start + step * Eigen::Vector2d(std::cos(a), std::sin(a));
          const double w = short_edge() ? -2.0 : worst(static_cast<int>(n));
          if (w > best + 1e-12) {
            best = w;
            moved = true;
            break;
          }
          x[n] = start;
        }
        if (!moved) step *= 0.5;
      }
    }
}

}  // namespace

double quad_corner_scaled_jacobian(const std::array<Eigen::Vector2d, 4>& q) {
  double m = 1.0;
  for (int j = 0; j < 4; ++j) {
    const Eigen::Vector2d e1 = q[(j + 1) % 4] - q[j], e2 = q[(j + 3) % 4] - q[j];
    const double l = e1.norm() * e2.norm();
    m = std::min(m, l > 0.0 ? cross(e1, e2) / l : -1.0);
  }
  return m;
}

std::string QuadLayout::explanation() const {
  std::ostringstream s;
  s << "quad layout: " << stats.patches << " patches, " << stats.ring_nodes << " nodes on the rings, "
    << stats.inner_nodes << " inside (valence";
  for (std::size_t v = 0; v < stats.valence.size(); ++v)
    if (stats.valence[v]) s << ' ' << v << (v == 7 ? "+" : "") << ": " << stats.valence[v];
  s << ")";
  if (stats.pillowed_rings) s << ", " << stats.pillowed_rings << " ring(s) pillowed";
  s << ", straight-sided scaled Jacobian min " << stats.min_corner_scaled_jacobian << " mean "
    << stats.mean_corner_scaled_jacobian
    << (stats.optimization_level == 3   ? ""
        : stats.optimization_level == 2 ? " (no edge rotations: they broke it)"
        : stats.optimization_level == 1 ? " (worst corners not optimized: that broke it)"
                                        : " (nodes not optimized: that tangled it)");
  return s.str();
}

QuadLayout build_quad_layout(const Domain& d, const QuadLayoutOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!quad_mesher_available()) quad_mesh({}, {});  // throws the InputError that explains it
  Eigen::Vector2d lo = d.outer.vertices.front(), hi = lo;
  for (const auto& v : d.outer.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double diam = (hi - lo).norm();
  SizeFieldOptions so = o.size;
  if (!(so.min_size > 0.0)) so.min_size = o.min_size_fraction * diam;
  const SizeField h(d, so);
  // Ring pieces are two quad edges long.
  auto piece_size = [&h](const Eigen::Vector2d& x) { return 2.0 * h(x); };

  std::vector<RingCurve> rings = {RingCurve(d.outer.vertices)};
  for (const Polygon& p : d.holes) rings.emplace_back(p.vertices);
  RingNodeOptions no = o.nodes;
  if (!(no.min_size > 0.0)) no.min_size = so.min_size;
  std::vector<std::vector<double>> nodes;
  for (const RingCurve& r : rings) nodes.push_back(ring_nodes(r, no, piece_size));

  std::vector<EdgeGrid::Edge> edges;
  for (std::size_t r = 0; r < rings.size(); ++r)
    for (std::size_t i = 0; i < rings[r].size(); ++i)
      edges.push_back({rings[r].vertex(i), rings[r].vertex(i + 1), static_cast<int>(r), i});
  const EdgeGrid grid(std::move(edges), lo, hi);
  const double tol = 1e-9 * diam;

  QuadLayout out;
  int level = 3;
  int repairs = 0;  // rounds that added nodes (dropping an optimization level is not one)
  for (int round = 0;; ++round) {
    // Optimized nodes that keep crossing the rings after many repairs: optimize less.
    if (repairs > 0 && repairs % 10 == 0 && level > 0 && repairs / 10 > 3 - level) {
      --level;
      out.stats.optimization_level = level;
    }
    if (repairs > o.max_repair_rounds)
      throw NumericalError("no quad layout found: the layout still crosses the boundary after " +
                           std::to_string(o.max_repair_rounds) + " rounds of adding nodes");
    std::vector<std::set<std::size_t>> to_split(rings.size());
    // The straight rings must be simple and disjoint: chords against chords.
    std::vector<std::vector<Eigen::Vector2d>> straight(rings.size());
    std::vector<EdgeGrid::Edge> chords;
    for (std::size_t r = 0; r < rings.size(); ++r) {
      for (double s : nodes[r]) straight[r].push_back(rings[r].point(s));
      for (std::size_t k = 0; k < straight[r].size(); ++k)
        chords.push_back({straight[r][k], straight[r][(k + 1) % straight[r].size()], static_cast<int>(r), k});
    }
    {
      const EdgeGrid cg(chords, lo, hi);
      for (std::size_t c = 0; c < chords.size(); ++c) {
        const auto& e = chords[c];
        for (int o2 : cg.near(e.a.cwiseMin(e.b), e.a.cwiseMax(e.b))) {
          if (o2 <= static_cast<int>(c)) continue;
          const auto& f = cg.edge(o2);
          const std::size_t n = straight[e.ring].size();
          const bool adjacent = f.ring == e.ring && (f.index == (e.index + 1) % n || e.index == (f.index + 1) % n);
          if (adjacent && n > 2) continue;
          if (segments_intersect(e.a, e.b, f.a, f.b)) {
            to_split[e.ring].insert(e.index);
            to_split[f.ring].insert(f.index);
          }
        }
      }
    }
    // Chords against the true rings (a chord may cut off a piece of another ring).
    for (const auto& e : chords)
      for (int g : grid.near(e.a.cwiseMin(e.b), e.a.cwiseMax(e.b))) {
        const auto& f = grid.edge(g);
        if (f.ring == e.ring) continue;
        if (segments_intersect(e.a, e.b, f.a, f.b)) {
          to_split[e.ring].insert(e.index);
          to_split[f.ring].insert(piece_of(nodes[f.ring], rings[f.ring].arc(f.index)));
        }
      }
    auto split_marked = [&]() {
      bool any = false;

      for (std::size_t r = 0; r < rings.size(); ++r) {
        // Split from the last piece down: indices of earlier pieces stay valid.
        for (auto it = to_split[r].rbegin(); it != to_split[r].rend(); ++it) {
          split_piece(rings[r], nodes[r], *it);
          any = true;
        }
      }
      return any;
    };
    if (split_marked()) {
      out.stats.repair_rounds = ++repairs;
      continue;
    }

    PlanarQuadMesh m;
    try {
      m = quad_mesh(straight, h);
    } catch (const NumericalError& e) {
      // Gmsh could not recover a boundary segment ("... on curve N ..."): that
      // piece and its neighbours get a node more, and the mesh is made again.
      const std::string what = e.what();
      const std::size_t at = what.find("on curve ");
      if (at == std::string::npos) throw;
      long long curve = std::atoll(what.c_str() + at + 9) - 1;  // line tags count the segments from 1
      std::size_t r = 0;
      while (r < straight.size() && curve >= static_cast<long long>(straight[r].size()))
        curve -= static_cast<long long>(straight[r].size()), ++r;
      if (r == straight.size() || curve < 0) throw;
      const std::size_t n = straight[r].size(), k = static_cast<std::size_t>(curve);
      for (const std::size_t j : {(k + n - 1) % n, k, (k + 1) % n}) to_split[r].insert(j);
      split_marked();
      out.stats.repair_rounds = ++repairs;
      continue;
    }
    // Boundary nodes onto the true rings.
    std::vector<Eigen::Vector2d> x = m.nodes;
    std::vector<double> arc(x.size(), 0.0);
    for (std::size_t n = 0; n < x.size(); ++n) {
      if (m.ring[n] < 0) continue;
      const auto& nr = nodes[m.ring[n]];
      const double L = rings[m.ring[n]].length();
      const std::size_t k = static_cast<std::size_t>(m.segment[n]);
      const double a = nr[k], b = k + 1 < nr.size() ? nr[k + 1] : nr.front() + L;
      arc[n] = rings[m.ring[n]].snap_to_vertex(a + m.t[n] * (b - a), 1e-3 * (b - a));
      x[n] = rings[m.ring[n]].point(arc[n]);
    }
    std::vector<std::array<int, 4>> quads = m.quads;
    std::vector<int> node_ring = m.ring;
    if (level >= 3) walk_flat_ring_corners(quads, x, node_ring, arc, rings);
    out.stats.pillowed_rings = pillow_flat_rings(quads, x, node_ring, arc, rings);
    if (level >= 3) free_sharp_tips(quads, x, node_ring, arc, rings);
    const std::vector<Eigen::Vector2d> x_start = x;  // the mesher's nodes, on the true rings
    const std::vector<double> arc_start = arc;
    if (level >= 1) {
      smooth_inner_nodes(x, quads, node_ring, arc, rings);
      for (int pass = 0; pass < 3; ++pass) {
        slide_ring_nodes(x, arc, quads, node_ring, rings);
        smooth_inner_nodes(x, quads, node_ring, arc, rings);
      }
    }
    if (level >= 2) improve_worst_corners(x, quads, node_ring, arc, rings);
    // Edges: shared by two quads (inner: cuts) or one (on a ring).
    const std::map<std::pair<int, int>, int> edge_quads = edge_uses(quads);
    std::vector<int> inner_degree(x.size(), 0), degree(x.size(), 0);
    for (const auto& [e, count] : edge_quads) {
      ++degree[e.first], ++degree[e.second];
      if (count == 2) ++inner_degree[e.first], ++inner_degree[e.second];
    }
    // Checks on the true geometry.
    auto mark_nearest_piece = [&](const Eigen::Vector2d& p) {
      double best = std::numeric_limits<double>::infinity();
      int br = 0;
      std::size_t be = 0;
      for (std::size_t r = 0; r < rings.size(); ++r)
        for (std::size_t i = 0; i < rings[r].size(); ++i) {
          const double dist = segment_distance(p, rings[r].vertex(i), rings[r].vertex(i + 1));
          if (dist < best) best = dist, br = static_cast<int>(r), be = i;
        }
      to_split[br].insert(piece_of(nodes[br], rings[br].arc(be)));
    };
    // The nodes involved in a violation: inner nodes outside the domain, the
    // ends of inner edges that cross a ring. Those the optimization moved go
    // back where the mesher put them; what still fails gets ring nodes more.
    auto violations = [&](bool mark) {
      std::set<int> involved;
      for (std::size_t n = 0; n < x.size(); ++n)
        if (node_ring[n] < 0 && grid.ray_crossings(x[n]) % 2 == 0) {
          involved.insert(static_cast<int>(n));
          if (mark) mark_nearest_piece(x[n]);
        }
      for (const auto& [e, count] : edge_quads) {
        if (count != 2) continue;
        const Eigen::Vector2d a = x[e.first], b = x[e.second];
        for (int g : grid.near(a.cwiseMin(b), a.cwiseMax(b))) {
          const auto& f = grid.edge(g);
          if (!segments_intersect(a, b, f.a, f.b)) continue;
          // Allowed: the cut's end on this ring edge, the rest of the cut off it.
          const bool a_on = node_ring[e.first] >= 0 && segment_distance(a, f.a, f.b) <= tol;
          const bool b_on = node_ring[e.second] >= 0 && segment_distance(b, f.a, f.b) <= tol;
          if (a_on != b_on) {
            const Eigen::Vector2d from = a_on ? a + 1e-6 * (b - a) : a, to = b_on ? b + 1e-6 * (a - b) : b;
            if (!segments_intersect(from, to, f.a, f.b)) continue;
          }
          involved.insert(e.first), involved.insert(e.second);
          if (mark) to_split[f.ring].insert(piece_of(nodes[f.ring], rings[f.ring].arc(f.index)));
        }
      }
      return involved;
    };
    for (int pass = 0; pass < 3; ++pass) {
      const std::set<int> bad = violations(false);
      bool changed = false;
      for (int n : bad)
        if (x[n] != x_start[n]) x[n] = x_start[n], arc[n] = arc_start[n], changed = true;
      if (!changed) break;
    }
    violations(true);
    if (split_marked()) {
      out.stats.repair_rounds = ++repairs;
      continue;
    }

    // The layout: inner edges are cuts, quad corners on rings without cuts are ring corners.
    std::vector<Cut> cuts;
    for (const auto& [e, count] : edge_quads) {
      if (count == 2) cuts.push_back({x[e.first], x[e.second]});
    }
    for (std::size_t n = 0; n < x.size(); ++n)
      if (node_ring[n] >= 0 && inner_degree[n] == 0 && degree[n] > 0) out.ring_corners.push_back(x[n]);
    try {
      out.layout = build_patch_layout(d, std::move(cuts), out.ring_corners);
      // Every patch corner convex where the map sees it (at the vertex itself).
      for (const Patch& p : out.layout.patches)
        for (int k = 0; k < 4; ++k) {
          const auto& v = p.polygon.vertices;
          const std::size_t c = p.corners[k], n = v.size();
          const Eigen::Vector2d a = v[(c + 1) % n] - v[c], b = v[(c + n - 1) % n] - v[c];
          // Between 1 and 170 degrees (sin 1 deg = 0.0175, sin 10 deg = 0.174): a corner
          // near 180 degrees leaves the patch map det J ~ 0 there.
          // (The mesher's own layout, level 0, only needs convex corners.)
          const double sn = cross(a, b) / (a.norm() * b.norm());
          const bool fine = level == 0 ? sn > 1e-3 : sn > 0.0175 && (a.dot(b) > 0.0 || sn > 0.174);
          if (!fine)
            throw InputError("a patch corner outside 1-170 degrees at " + std::to_string(v[c].x()) + ", " +
                             std::to_string(v[c].y()));
        }
    } catch (const InputError& e) {
      // The optimization tangled the layout somewhere (a tangled start near
      // rings much closer than the patch size, or a corner turned reflex):
      // the same mesh, optimized less (level 3: all; 2: no edge rotations (flat
      // corners walked, sharp tips freed); 1: smoothing and sliding only; 0: the
      // mesher's nodes).
      if (level == 0) {
        // Two cuts of the mesher's own layout cross (the true rings are far
        // from their chords there): ring nodes more near the place, and again.
        const std::string what = e.what();
        const std::size_t at = what.find("cross near (");
        if (at == std::string::npos || repairs >= o.max_repair_rounds)
          throw NumericalError("no valid quad layout: " + what);
        const char* p = what.c_str() + at + 12;
        char* end = nullptr;
        const double px = std::strtod(p, &end);
        const double py = end && *end == ',' ? std::strtod(end + 1, nullptr) : 0.0;
        mark_nearest_piece(Eigen::Vector2d(px, py));
        split_marked();
        out.ring_corners.clear();
        out.stats.repair_rounds = ++repairs;
        level = 3;  // the new mesh is optimized again
        out.stats.optimization_level = level;
        continue;
      }
      --level;
      out.ring_corners.clear();
      out.stats.optimization_level = level;
      continue;
    }
    QuadLayoutStats& st = out.stats;
    st.patches = out.layout.patches.size();
    st.min_size = so.min_size;
    st.max_size = so.max_size > 0.0 ? so.max_size : 0.125 * diam;
    for (std::size_t n = 0; n < x.size(); ++n) {
      if (degree[n] == 0) continue;
      if (node_ring[n] >= 0) ++st.ring_nodes;
      else ++st.inner_nodes, ++st.valence[std::min(degree[n], 7)];
    }
    double sum = 0.0;
    st.min_corner_scaled_jacobian = 1.0;
    for (const auto& q : quads) {
      const double sj = quad_corner_scaled_jacobian({x[q[0]], x[q[1]], x[q[2]], x[q[3]]});
      st.min_corner_scaled_jacobian = std::min(st.min_corner_scaled_jacobian, sj);
      sum += sj;
    }
    st.mean_corner_scaled_jacobian = sum / static_cast<double>(quads.size());
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  }
}

}  // namespace tspline
