#include "tspline/layout/layout_topology.h"

#include <algorithm>
#include <cstdlib>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "layout_local.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/layout/layout_optimizer.h"

namespace tspline {

double layout_quad_figure(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int q) {
  double f = Q.quad(m, t, q).mean_ratio;
  for (int j = 0; j < 4; ++j) f = std::min(f, Q.side_shape(m, t, q, j));
  return f;
}

namespace layout_local {

bool has_edge(const LayoutMesh& m, const LayoutTopology& t, int a, int b) {
  for (const auto& [q, j] : t.corners_of(a))
    if (m.quads[q][(j + 1) % 4] == b || m.quads[q][(j + 3) % 4] == b) return true;
  return false;
}

// The nodes of the quads around `nodes` (their one-ring), each once.
std::vector<int> one_ring(const LayoutMesh& m, const LayoutTopology& t, const std::vector<int>& nodes) {
  std::vector<int> out;
  std::vector<char> seen(m.size(), 0);
  for (const int n : nodes)
    for (const auto& [q, j] : t.corners_of(n))
      for (const int v : m.quads[q])
        if (!seen[v]) seen[v] = 1, out.push_back(v);
  return out;
}

double region_figure(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, const std::vector<int>& nodes) {
  double f = 1.0;
  std::vector<int> quads;
  for (const int n : nodes)
    for (const auto& [q, j] : t.corners_of(n)) quads.push_back(q);
  std::sort(quads.begin(), quads.end());
  quads.erase(std::unique(quads.begin(), quads.end()), quads.end());
  for (const int q : quads) f = std::min(f, layout_quad_figure(m, t, Q, q));
  return f;
}

// The patch corners of the quads at the given nodes that the layout's final
// check rejects (patch_corner_in_range, at the node itself: the ring's own
// edge, or the straight cut). All four corners of each quad: a node's move
// turns its neighbours' corners too.
int rejected_corners(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q,
                     const std::vector<int>& nodes) {
  std::vector<int> quads;
  for (const int n : nodes)
    for (const auto& [q, j] : t.corners_of(n)) quads.push_back(q);
  std::sort(quads.begin(), quads.end());
  quads.erase(std::unique(quads.begin(), quads.end()), quads.end());
  int count = 0;
  for (const int q : quads)
    for (int j = 0; j < 4; ++j) {
      const auto [a, b] = Q.corner_vectors(m, t, q, j, 0.0);
      if (!Q.corner_in_range(a, b)) ++count;
    }
  return count;
}

double corner_sj(const Eigen::Vector2d& p, const Eigen::Vector2d& next, const Eigen::Vector2d& prev) {
  const Eigen::Vector2d e1 = next - p, e2 = prev - p;
  const double l = e1.norm() * e2.norm();
  return l > 0.0 ? (e1.x() * e2.y() - e1.y() * e2.x()) / l : -1.0;
}

LocalLayout local_layout(const LayoutMesh& m, const LayoutTopology& t, const std::vector<int>& reach) {
  LocalLayout l;
  for (const int n : reach)
    for (const auto& [q, j] : t.corners_of(n)) l.quad.push_back(q);
  std::sort(l.quad.begin(), l.quad.end());
  l.quad.erase(std::unique(l.quad.begin(), l.quad.end()), l.quad.end());
  for (const int q : l.quad) l.node.insert(l.node.end(), m.quads[q].begin(), m.quads[q].end());
  std::sort(l.node.begin(), l.node.end());
  l.node.erase(std::unique(l.node.begin(), l.node.end()), l.node.end());
  for (const int n : l.node) l.mesh.x.push_back(m.x[n]), l.mesh.ring.push_back(m.ring[n]), l.mesh.arc.push_back(m.arc[n]);
  for (const int q : l.quad) {
    std::array<int, 4> c;
    for (int j = 0; j < 4; ++j) c[j] = LocalLayout::local(l.node, m.quads[q][j]);
    l.mesh.quads.push_back(c);
  }
  return l;
}

}  // namespace layout_local

using namespace layout_local;

std::vector<int> flat_ring_corners(const LayoutMesh& m, const LayoutQuality& Q) {
  const LayoutTopology t(m);
  std::vector<int> flat;
  for (std::size_t v = 0; v < m.size(); ++v) {
    if (m.ring[v] < 0 || t.valence(static_cast<int>(v)) != 1) continue;
    const auto [q, j] = t.corners_of(static_cast<int>(v)).front();
    // Flat: an obtuse corner with sin below 1/2 (above 150 degrees), at any of
    // the scales the corner is measured at; or reflex.
    for (const double scale : LayoutQuality::corner_scales) {
      const auto [e1, e2] = Q.corner_vectors(m, t, q, j, scale);
      const double sn = corner_sj(Eigen::Vector2d::Zero(), e1, e2);
      if (sn < 0.0 || (sn <= 0.5 && e1.dot(e2) < 0.0)) {
        flat.push_back(static_cast<int>(v));
        break;
      }
    }
  }
  return flat;
}

std::vector<char> rings_with_flat_corners(const LayoutMesh& m, const LayoutQuality& Q) {
  std::vector<char> flat(Q.rings().curves.size(), 0);
  for (const int v : flat_ring_corners(m, Q)) flat[m.ring[v]] = 1;
  return flat;
}

namespace {

// One sheet of quads through the single quad at a flat ring corner v
// (insert_corner_sheets). The quad (v, b, X, a) is cut into three: (a, v, v', a'),
// (v, b, b', v') and (v', b', X, a'), with a' and b' at the midpoints of X-a and
// b-X and v' between v and X; from each of a' and b' the sheet runs on through
// the quads across, each cut in two between the midpoints of the edge it enters
// by and of the opposite edge, until it reaches a ring, where the midpoint (by
// arc length) of the ring piece becomes a ring node of two quads. A sheet
// whose walk out through X-a comes back into the corner's quad through b-X is
// closed: it cuts the quads of that loop and reaches no ring.
class CornerSheet {
 public:
  CornerSheet(LayoutMesh& m, const LayoutRings& R) : m_(m), R_(R) {}

  // The quads the sheet adds: 0 where v is the corner of more than one quad
  // already (an earlier sheet ran through its quad; m unchanged), none where
  // the sheet would run through one quad twice in the same direction, or
  // through the corner's quad again other than as a closed loop, or cut more
  // than max_quads quads (m unchanged). A sheet that crosses itself (through
  // a quad in both directions) cuts that quad in four.
  std::optional<std::size_t> insert(int v, std::size_t max_quads) {
    const LayoutTopology t(m_);
    if (t.valence(v) != 1) return 0;
    const auto [q, j] = t.corners_of(v).front();
    crossed_.assign(m_.quads.size(), 0);
    entry_.assign(m_.quads.size(), {0, 0});
    crossed_[q] = kCornerQuad;
    // Out through X-a first. A sheet that comes back into the corner's quad
    // through b-X is a closed loop: the same path as the walk out through b-X.
    switch (walk(t, q, (j + 2) % 4, (j + 1) % 4, max_quads)) {
      case Walk::kFailed: return std::nullopt;
      case Walk::kClosed: break;
      case Walk::kToRing:
        if (walk(t, q, (j + 1) % 4, -1, max_quads) != Walk::kToRing) return std::nullopt;
    }
    const std::array<int, 4> Qv = m_.quads[q];
    const int b = Qv[(j + 1) % 4], X = Qv[(j + 2) % 4], a = Qv[(j + 3) % 4];
    const int ap = edge_node(t, q, (j + 2) % 4), bp = edge_node(t, q, (j + 1) % 4);
    // The quad is a triangle a, b, X with v on its side a-b: v' at its centroid.
    const int vp = add_node((m_.x[a] + m_.x[b] + m_.x[X]) / 3.0, -1, 0.0);
    const std::size_t before = m_.quads.size();
    m_.quads[q] = {a, v, vp, ap};
    m_.quads.push_back({v, b, bp, vp});
    m_.quads.push_back({vp, bp, X, ap});
    for (const int n : order_) {
      const std::array<int, 4> N = m_.quads[n];
      if (crossed_[n] == 3) {  // both directions: four quads around a new middle node
        std::array<int, 4> mid;
        for (int e = 0; e < 4; ++e) mid[e] = edge_node(t, n, e);
        const int c = add_node(0.25 * (m_.x[N[0]] + m_.x[N[1]] + m_.x[N[2]] + m_.x[N[3]]), -1, 0.0);
        m_.quads[n] = {N[0], mid[0], c, mid[3]};
        m_.quads.push_back({mid[0], N[1], mid[1], c});
        m_.quads.push_back({c, mid[1], N[2], mid[2]});
        m_.quads.push_back({mid[3], c, mid[2], N[3]});
        continue;
      }
      const int k = entry_[n][crossed_[n] == 1 ? 0 : 1];
      const int p = edge_node(t, n, k), r = edge_node(t, n, (k + 2) % 4);
      m_.quads[n] = {N[k], p, r, N[(k + 3) % 4]};
      m_.quads.push_back({p, N[(k + 1) % 4], N[(k + 2) % 4], r});
    }
    return m_.quads.size() - before;
  }

 private:
  static constexpr char kCornerQuad = 4;

  enum class Walk { kToRing, kClosed, kFailed };

  // From quad q out through its edge e, quad after quad across the opposite
  // edges, to a ring; or back into the corner's quad through its edge
  // `closing` (a closed sheet).
  Walk walk(const LayoutTopology& t, int q, int e, int closing, std::size_t max_quads) {
    while (!t.on_ring(q, e)) {
      const auto [n, k] = t.across(q, e);
      if (n >= 0 && crossed_[n] == kCornerQuad && k == closing) return Walk::kClosed;
      const char axis = static_cast<char>(1 << (k % 2));
      if (n < 0 || (crossed_[n] & (axis | kCornerQuad)) || order_.size() + 2 > max_quads) return Walk::kFailed;
      if (!crossed_[n]) order_.push_back(n);
      crossed_[n] |= axis;
      entry_[n][k % 2] = k;
      q = n, e = (k + 2) % 4;
    }
    return Walk::kToRing;
  }

  int add_node(const Eigen::Vector2d& x, int ring, double arc) {
    m_.x.push_back(x);
    m_.ring.push_back(ring);
    m_.arc.push_back(arc);
    return static_cast<int>(m_.x.size()) - 1;
  }

  // The node at the midpoint of edge e of quad q (made once per edge): on a
  // ring edge, the point halfway along the ring piece between its two nodes.
  int edge_node(const LayoutTopology& t, int q, int e) {
    const int u = m_.quads[q][e], w = m_.quads[q][(e + 1) % 4];
    const std::pair<int, int> key = std::minmax(u, w);
    for (const auto& [k, node] : made_)
      if (k == key) return node;
    int node;
    if (t.on_ring(q, e)) {
      const int r = m_.ring[u];
      const RingCurve& ring = R_.curves[static_cast<std::size_t>(r)];
      const double L = ring.length();
      // A counter-clockwise quad runs along the outer ring forwards, along a hole backwards.
      double s0 = m_.arc[u], s1 = m_.arc[w];
      if (R_.direction(r) < 0.0) std::swap(s0, s1);
      double len = s1 - s0;
      if (len <= 0.0) len += L;
      const double s = ring.snap_to_vertex(std::fmod(s0 + 0.5 * len, L), 0.01 * len);
      node = add_node(ring.point(s), r, s);
    } else {
      node = add_node(0.5 * (m_.x[u] + m_.x[w]), -1, 0.0);
    }
    made_.push_back({key, node});
    return node;
  }

  LayoutMesh& m_;
  const LayoutRings& R_;
  std::vector<std::pair<std::pair<int, int>, int>> made_;  // (edge, its midpoint node), a handful per sheet
  std::vector<char> crossed_;                 // per quad: directions the sheet runs through it (bits 1, 2), or kCornerQuad
  std::vector<std::array<int, 2>> entry_;     // per quad and direction: the edge the sheet enters by
  std::vector<int> order_;                    // the quads the sheet runs through, each once
};

}  // namespace

std::size_t insert_corner_sheets(LayoutMesh& m, const LayoutRings& R, const std::vector<int>& corners,
                                 std::size_t max_quads) {
  LayoutMesh trial = m;
  std::size_t added = 0;
  for (const int v : corners) {
    const std::optional<std::size_t> k = CornerSheet(trial, R).insert(v, max_quads - added);
    if (!k) return 0;
    added += *k;
    if (added > max_quads) return 0;  // (the walk counts a quad cut in four as one)
  }
  m = std::move(trial);
  return added;
}

namespace {

// One pillowing (pillow_rings): each pillowed ring node gets a copy on the
// ring, the old node moves inside, and each ring edge gets a layer quad
// between the two.
class Pillowing {
 public:
  Pillowing(LayoutMesh& m, const std::vector<char>& pillow) : m_(m), pillow_(pillow), n0_(m.size()) {
    quads_of_.resize(n0_);
    for (std::size_t q = 0; q < m.quads.size(); ++q)
      for (int j = 0; j < 4; ++j) quads_of_[m.quads[q][j]].push_back(static_cast<int>(q));
  }

  void run() {
    const std::vector<std::pair<int, int>> along = pillowed_ring_edges();
    copy_ring_nodes();
    move_old_ring_nodes_inside();
    add_layer_quads(along);
    std::vector<char> resplit(m_.quads.size(), 0);  // old quads already part of a hexagon
    for (std::size_t v = 0; v < n0_; ++v) keep_one_quad_at_tip(static_cast<int>(v), resplit);
  }

 private:
  // Edges along the pillowed rings, as directed in their quad.
  std::vector<std::pair<int, int>> pillowed_ring_edges() const {
    const LayoutTopology t(m_);
    std::vector<std::pair<int, int>> along;
    for (std::size_t q = 0; q < m_.quads.size(); ++q)
      for (int j = 0; j < 4; ++j) {
        const int v = m_.quads[q][j], w = m_.quads[q][(j + 1) % 4];
        if (t.on_ring(static_cast<int>(q), j) && m_.ring[v] >= 0 && m_.ring[w] == m_.ring[v] && pillow_[m_.ring[v]])
          along.push_back({v, w});
      }
    return along;
  }

  void copy_ring_nodes() {
    copy_.assign(n0_, -1);
    for (std::size_t v = 0; v < n0_; ++v) {
      if (m_.ring[v] < 0 || !pillow_[m_.ring[v]]) continue;
      copy_[v] = static_cast<int>(m_.x.size());
      m_.x.push_back(m_.x[v]);
      m_.ring.push_back(m_.ring[v]);
      m_.arc.push_back(m_.arc[v]);
    }
  }

  // The old ring nodes move a third of the way towards the mean of their other quad corners.
  void move_old_ring_nodes_inside() {
    for (std::size_t v = 0; v < n0_; ++v) {
      if (copy_[v] < 0) continue;
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      int k = 0;
      for (int q : quads_of_[v])
        for (int j = 0; j < 4; ++j)
          if (m_.quads[q][j] != static_cast<int>(v)) mean += m_.x[m_.quads[q][j]], ++k;
      if (k > 0) m_.x[v] += (1.0 / 3.0) * (mean / k - m_.x[v]);
      m_.ring[v] = -1;
    }
  }

  // The layer quad of each ring edge, by the edge's first node in its quad.
  void add_layer_quads(const std::vector<std::pair<int, int>>& along) {
    layer_from_.assign(n0_, -1);
    layer_to_.assign(n0_, -1);
    for (const auto& [v, w] : along) {
      layer_from_[v] = static_cast<int>(m_.quads.size());
      layer_to_[w] = static_cast<int>(m_.quads.size());
      m_.quads.push_back({w, v, copy_[v], copy_[w]});
    }
  }

  // A tip keeps one quad: where a node was the corner of one quad only, with
  // a corner below 150 degrees (a convex tip of the coast, not the flat corner
  // the layer is for), its two layer quads and its old quad form a hexagon
  // a, a_r, v_r, b_r, b, X around the moved node v, which goes; the hexagon is
  // split by whichever of a_r-b and a-b_r gives the better worst corner (with
  // straight sides; it may be folded where the moved nodes crowd a thin tip:
  // the node optimization that follows untangles it, and the checks on the
  // true geometry still hold the layout to account).
  void keep_one_quad_at_tip(int v, std::vector<char>& resplit) {
    auto& quads = m_.quads;
    const auto& x = m_.x;
    const int n0 = static_cast<int>(n0_);
    if (copy_[v] < 0 || quads_of_[v].size() != 1 || layer_from_[v] < 0 || layer_to_[v] < 0) return;
    const int q = quads_of_[v].front();
    if (resplit[q]) return;
    int j = 0;
    while (j < 4 && quads[q][j] != v) ++j;
    if (j == 4) return;
    const int b = quads[q][(j + 1) % 4], X = quads[q][(j + 2) % 4], a = quads[q][(j + 3) % 4];
    if (b >= n0 || a >= n0 || copy_[a] < 0 || copy_[b] < 0) return;
    const Eigen::Vector2d tip = x[copy_[v]];
    const double sn = corner_sj(tip, x[copy_[b]], x[copy_[a]]);
    if (!(sn > 0.5 || (sn > 0.0 && (x[copy_[b]] - tip).dot(x[copy_[a]] - tip) > 0.0))) return;
    const int ar = copy_[a], vr = copy_[v], br = copy_[b];
    const std::array<std::array<int, 4>, 2> split_a = {{{ar, vr, br, b}, {b, X, a, ar}}};
    const std::array<std::array<int, 4>, 2> split_b = {{{a, ar, vr, br}, {br, b, X, a}}};
    auto worst = [&](const std::array<std::array<int, 4>, 2>& s2) {
      double w = 1.0;
      for (const auto& qq : s2)
        for (int k = 0; k < 4; ++k) w = std::min(w, corner_sj(x[qq[k]], x[qq[(k + 1) % 4]], x[qq[(k + 3) % 4]]));
      return w;
    };
    const auto& best = worst(split_a) >= worst(split_b) ? split_a : split_b;
    const int kept = layer_from_[v], gone = layer_to_[v];
    resplit[q] = 1;
    quads[q] = best[0];
    quads[kept] = best[1];
    // Neither is a layer quad any more; `gone` is removed, the last quad takes its place.
    for (std::vector<int>* l : {&layer_from_, &layer_to_})
      for (int& f : *l)
        if (f == kept || f == gone) f = -1;
    const int last = static_cast<int>(quads.size()) - 1;
    if (gone != last) {
      quads[gone] = quads[last];
      for (std::vector<int>* l : {&layer_from_, &layer_to_})
        for (int& f : *l)
          if (f == last) f = gone;
    }
    quads.pop_back();
  }

  LayoutMesh& m_;
  const std::vector<char>& pillow_;
  const std::size_t n0_;                     // nodes before the pillowing
  std::vector<std::vector<int>> quads_of_;   // the quads at each old node
  std::vector<int> copy_;                    // the ring copy of each pillowed node (-1: none)
  std::vector<int> layer_from_, layer_to_;   // the layer quad whose ring edge starts / ends at a node
};

}  // namespace

std::size_t pillow_rings(LayoutMesh& m, const std::vector<char>& pillow) {
  std::size_t count = 0;
  for (const char p : pillow) count += p;
  if (count == 0) return 0;
  Pillowing(m, pillow).run();
  return count;
}

namespace {

// The best rotation around quad q (the mesh itself is not changed): the new
// corners of q and of the quad across the rotated edge, and where the nodes
// around them end after their optimization.
struct RotationTry {
  std::size_t tried = 0;
  int other = -1;  ///< the quad across the edge rotated, -1 if no rotation is better
  std::array<int, 4> quad_q{}, quad_other{};
  std::vector<int> free;  ///< the nodes optimized around the rotation
  std::vector<Eigen::Vector2d> x;
  std::vector<double> arc;
  bool blocked = false;  ///< an edge was not tried: the quad across it already rotated this round
};

// The best rotation around quad q of the layout (which is not changed), tried
// on the local layout of the nodes it reads: the new corners of q and of the
// quad across the rotated edge, and where the nodes around them end after
// their optimization (global indices).
RotationTry try_rotations(const LayoutMesh& whole, const LayoutTopology& whole_t, const LayoutQuality& Q,
                          const LayoutAdmissible& admissible, const std::vector<char>& touched, int q_global,
                          const std::vector<int>& reach, const LayoutOptimizationOptions& lo) {
  const LocalLayout l = local_layout(whole, whole_t, reach);
  const LayoutMesh& m = l.mesh;
  const LayoutTopology t(m);
  const int q = LocalLayout::local(l.quad, q_global);
  RotationTry out;
  double best = -1e300, before = 0.0;
  for (int j = 0; j < 4; ++j) {
    if (t.on_ring(q, j)) continue;
    const auto [b, k] = t.across(q, j);
    if (b < 0) continue;
    if (touched[l.quad[b]]) {
      out.blocked = true;
      continue;
    }
    // Only between quads that run along their shared edge in opposite directions.
    if (m.quads[b][k] != m.quads[q][(j + 1) % 4]) continue;
    // The hexagon, counter-clockwise, the shared edge h0-h3.
    const std::array<int, 4>& A = m.quads[q];
    const std::array<int, 4>& B = m.quads[b];
    const std::array<int, 6> h = {A[j], B[(k + 2) % 4], B[(k + 3) % 4], A[(j + 1) % 4], A[(j + 2) % 4],
                                  A[(j + 3) % 4]};
    {
      std::array<int, 6> sorted = h;
      std::sort(sorted.begin(), sorted.end());
      if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;
    }
    const std::vector<int> hex(h.begin(), h.end());
    const std::vector<int> free = one_ring(m, t, hex);
    if (best == -1e300) before = region_figure(m, t, Q, free);
    const int rejected_before = rejected_corners(m, t, Q, free);
    for (const int r : {1, 2}) {
      // Diagonal h_r - h_{r+3}; the shared edge's ends lose one quad each.
      const int d0 = h[r], d1 = h[r + 3];
      bool ok = !has_edge(m, t, d0, d1);
      for (const int e : {h[0], h[3]})
        if (m.ring[e] < 0 && t.valence(e) <= 3) ok = false;
      if (!ok) continue;
      LayoutMesh c = m;
      c.quads[q] = {h[r], h[r + 1], h[r + 2], h[r + 3]};
      c.quads[b] = {h[(r + 3) % 6], h[(r + 4) % 6], h[(r + 5) % 6], h[r]};
      optimize_layout_nodes(c, Q, admissible, free, lo);
      ++out.tried;
      const LayoutTopology ct(c);
      bool valid = true;
      for (const int n : free) valid = valid && admissible(c, ct, n);
      // Never more corners that the final check rejects: a tangled
      // neighbourhood's worst figure can rise while a ring node is left the
      // corner of one quad on a straight coast, which no node move mends.
      if (!valid || rejected_corners(c, ct, Q, free) > rejected_before) continue;
      const double after = region_figure(c, ct, Q, free);
      if (after > best) {
        best = after;
        out.other = l.quad[b];
        for (int i = 0; i < 4; ++i) out.quad_q[i] = l.node[c.quads[q][i]], out.quad_other[i] = l.node[c.quads[b][i]];
        out.free.clear(), out.x.clear(), out.arc.clear();
        for (const int n : free) out.free.push_back(l.node[n]), out.x.push_back(c.x[n]), out.arc.push_back(c.arc[n]);
      }
    }
  }
  if (!(out.other >= 0 && best > before + 1e-3)) out.other = -1;
  return out;
}

// The nodes a rotation try around quad q reads: the quads around the nodes it
// may move (the one-ring of q and of its neighbours) and their nodes.
// (A set, sorted: its cost does not grow with the layout.)
std::vector<int> try_reach(const LayoutMesh& m, const LayoutTopology& t, int q) {
  std::vector<int> nodes(m.quads[q].begin(), m.quads[q].end());
  for (int j = 0; j < 4; ++j) {
    const int b = t.across(q, j).first;
    if (b >= 0) nodes.insert(nodes.end(), m.quads[b].begin(), m.quads[b].end());
  }
  for (int ring = 0; ring < 2; ++ring) {
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    std::vector<int> next;
    for (const int n : nodes)
      for (const auto& [a, j] : t.corners_of(n)) next.insert(next.end(), m.quads[a].begin(), m.quads[a].end());
    nodes = std::move(next);
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

}  // namespace

LayoutRotationReport rotate_layout_edges(LayoutMesh& m, const LayoutQuality& Q, const LayoutAdmissible& admissible,
                                         const LayoutRotationOptions& o) {
  LayoutRotationReport report;
  const LayoutOptimizationOptions lo{.max_sweeps = o.local_sweeps, .cancel = o.cancel};
  std::vector<char> reached(m.size(), 0);
  // A try that found no better rotation (and was not blocked) is not made
  // again while no node it reads has moved or changed quads since: it would
  // find the same. Stamps count batches.
  std::vector<std::size_t> node_stamp(m.size(), 0), failed_at(m.quads.size(), 0);
  std::size_t clock = 0;
  for (int round = 0; round < o.rounds; ++round) {
    LayoutTopology t(m);
    std::vector<std::pair<double, int>> bad;
    for (std::size_t q = 0; q < m.quads.size(); ++q) {
      const double f = layout_quad_figure(m, t, Q, static_cast<int>(q));
      if (f < o.target) bad.push_back({f, static_cast<int>(q)});
    }
    if (bad.empty()) break;
    std::sort(bad.begin(), bad.end());
    if (bad.size() > o.max_quads) bad.resize(o.max_quads);
    std::vector<char> touched(m.quads.size(), 0);
    std::size_t kept = 0;
    // The quads in order, in batches whose tries read disjoint sets of nodes:
    // each batch's tries run on the pool's threads, on copies of the layout,
    // and are kept in order; the result is that of trying them one by one.
    // A quad whose try reads a node that an earlier quad's try (in the batch,
    // or left for a later batch) may read waits for a later batch; quads past
    // it that read none of those nodes join this one: tries that read
    // disjoint nodes give the same result in either order.
    const std::size_t max_batch = std::max<std::size_t>(1, o.max_batch);
    std::vector<char> done(bad.size(), 0);
    for (std::size_t i = 0; i < bad.size();) {
      throw_if_cancelled(o.cancel);
      ++clock;
      std::vector<int> batch;
      std::vector<std::vector<int>> reaches;
      std::vector<int> marked;
      const std::size_t window = std::min(bad.size(), i + 4 * max_batch);
      for (std::size_t k = i; k < window && batch.size() < max_batch; ++k) {
        if (done[k]) continue;
        const int q = bad[k].second;
        if (touched[q]) {
          done[k] = 1;
          continue;
        }
        std::vector<int> reach = try_reach(m, t, q);
        const bool clear = std::none_of(reach.begin(), reach.end(), [&](int n) { return reached[n] != 0; });
        // (Only once no earlier quad waiting or batched may move what it reads.)
        if (clear && o.skip_known_failures && failed_at[q] != 0 &&
            std::all_of(reach.begin(), reach.end(), [&](int n) { return node_stamp[n] <= failed_at[q]; })) {
          done[k] = 1;
          continue;
        }
        for (const int n : reach)
          if (!reached[n]) reached[n] = 1, marked.push_back(n);
        if (!clear) continue;
        done[k] = 1;
        batch.push_back(q);
        reaches.push_back(std::move(reach));
      }
      for (const int n : marked) reached[n] = 0;
      while (i < bad.size() && done[i]) ++i;
      std::vector<RotationTry> tries(batch.size());
      // (Handed out one at a time: a try's cost varies with its neighbourhood.)
      detail::parallel_items(batch.size(), detail::pool_threads(), [&](std::size_t k) {
        tries[k] = try_rotations(m, t, Q, admissible, touched, batch[k], reaches[k], lo);
      });
      bool changed = false;
      for (std::size_t k = 0; k < batch.size(); ++k) {
        const RotationTry& r = tries[k];
        report.tried += r.tried;
        const int q = batch[k];
        if (r.other < 0) {
          if (!r.blocked) failed_at[q] = clock;
          continue;
        }
        for (const int n : r.free) node_stamp[n] = clock;
        m.quads[q] = r.quad_q, m.quads[r.other] = r.quad_other;
        for (std::size_t f = 0; f < r.free.size(); ++f) m.x[r.free[f]] = r.x[f], m.arc[r.free[f]] = r.arc[f];
        touched[q] = touched[r.other] = 1;
        report.moved.insert(report.moved.end(), r.free.begin(), r.free.end());
        ++kept;
        changed = true;
      }
      if (changed) t = LayoutTopology(m);
    }
    report.kept += kept;
    if (kept == 0) break;
  }
  std::sort(report.moved.begin(), report.moved.end());
  report.moved.erase(std::unique(report.moved.begin(), report.moved.end()), report.moved.end());
  return report;
}

}  // namespace tspline
