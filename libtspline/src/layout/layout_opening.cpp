// Openings of wide ring corners (layout_topology.h: open_wide_ring_corners).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "layout_local.h"
#include "tspline/boundary/plane.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/layout/layout_optimizer.h"
#include "tspline/layout/layout_topology.h"

namespace tspline {
namespace {

using namespace layout_local;

// The widest patch corner at node n, at the node itself (degrees).
double widest_corner(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n) {
  double w = 0.0;
  for (const auto& [q, j] : t.corners_of(n)) {
    const auto [a, b] = Q.corner_vectors(m, t, q, j, 0.0);
    w = std::max(w, ccw_degrees(a, b));
  }
  return w;
}

// The quads around inner node c counter-clockwise, starting with the one whose
// edge leaves c towards `from`, and the spokes: spokes[i] is the node at the
// start of fan[i] (spokes[0] == from). False if the fan does not close (c on a
// ring, or a quad not found).
bool fan_around(const LayoutMesh& m, const LayoutTopology& t, int c, int from, std::vector<int>& fan,
                std::vector<int>& spokes) {
  fan.clear(), spokes.clear();
  auto quad_from = [&](int spoke) {
    for (const auto& [q, j] : t.corners_of(c))
      if (m.quads[q][(j + 1) % 4] == spoke) return std::make_pair(q, j);
    return std::make_pair(-1, -1);
  };
  int spoke = from;
  for (std::size_t k = 0; k < t.valence(c); ++k) {
    const auto [q, j] = quad_from(spoke);
    if (q < 0) return false;
    fan.push_back(q), spokes.push_back(spoke);
    spoke = m.quads[q][(j + 3) % 4];
  }
  return spoke == from;
}

// Nodes within `rings` quad rings of the seeds.
std::vector<int> rings_around(const LayoutMesh& m, const LayoutTopology& t, std::vector<int> nodes, int rings) {
  for (int r = 0; r < rings; ++r) nodes = one_ring(m, t, nodes);
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

struct Opening {
  double figure = -std::numeric_limits<double>::infinity();
  LocalLayout local;  // the local layout with the opening made and its nodes optimized
  std::vector<int> free;  // local ids of the nodes optimized
};

// The best opening at ring node n (global id ln in `base`, the local layout
// of everything its tries read), if one raises the figure around it.
Opening best_opening(const LocalLayout& base, int ln, const LayoutQuality& Q,
                     const LayoutAdmissible& admissible, const LayoutOptimizationOptions& lo,
                     std::size_t& tried) {
  const LayoutTopology bt(base.mesh);
  std::vector<int> inner;
  for (const auto& [q, j] : bt.corners_of(ln))
    for (const int k : {1, 3}) {
      const int c = base.mesh.quads[q][(j + k) % 4];
      if (base.mesh.ring[c] < 0 && bt.valence(c) >= 4 &&
          std::find(inner.begin(), inner.end(), c) == inner.end())
        inner.push_back(c);
    }
  Opening best;
  std::vector<int> fan, spokes;
  for (const int c : inner) {
    if (!fan_around(base.mesh, bt, c, ln, fan, spokes)) continue;
    const std::size_t V = fan.size();
    for (std::size_t i = 2; i + 2 <= V; ++i) {
      const int y = spokes[i];
      const std::vector<int> around = {ln, c, y};
      const std::vector<int> region_before = one_ring(base.mesh, bt, around);
      const double before = region_figure(base.mesh, bt, Q, region_before);
      // Only where the quads around are untangled: in a folded neighbourhood
      // a higher worst figure says little of the corners the opening makes.
      if (!(before > 0.0)) continue;
      const int rejected_before = rejected_corners(base.mesh, bt, Q, region_before);
      Opening o2;
      o2.local = base;
      LayoutMesh& lm = o2.local.mesh;
      // c keeps the quads fan[0..i) (from n to y), its copy c2 takes the others.
      const int c2 = static_cast<int>(lm.size());
      const Eigen::Vector2d xc = lm.x[c];
      Eigen::Vector2d d1 = Eigen::Vector2d::Zero(), d2 = Eigen::Vector2d::Zero();
      double spoke_length = 0.0;
      for (std::size_t k = 0; k < V; ++k) {
        Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
        for (const int v : lm.quads[fan[k]]) centroid += lm.x[v] / 4.0;
        (k < i ? d1 : d2) += (centroid - xc).normalized();
        spoke_length += (lm.x[spokes[k]] - xc).norm() / static_cast<double>(V);
      }
      for (std::size_t k = i; k < V; ++k)
        for (int& v : lm.quads[fan[k]])
          if (v == c) v = c2;
      // Start a third of the spoke length apart, each towards its own quads;
      // the optimizer below places them.
      const double step = spoke_length / 6.0;
      lm.x.push_back(xc + step * (d2.norm() > 0.0 ? d2.normalized() : Eigen::Vector2d::Zero()));
      lm.x[c] = xc + step * (d1.norm() > 0.0 ? d1.normalized() : Eigen::Vector2d::Zero());
      lm.ring.push_back(-1);
      lm.arc.push_back(0.0);
      lm.quads.push_back({ln, c, y, c2});  // counter-clockwise: c is on the side of fan[0], from n to y
      const LayoutTopology nt(lm);
      o2.free = one_ring(lm, nt, {ln, c, c2, y});
      optimize_layout_nodes(lm, Q, admissible, o2.free, lo);
      ++tried;
      bool valid = true;
      for (const int v : o2.free) valid = valid && admissible(lm, nt, v);
      if (!valid || rejected_corners(lm, nt, Q, o2.free) > rejected_before) continue;
      o2.figure = region_figure(lm, nt, Q, o2.free);
      if (o2.figure > before + 1e-3 && o2.figure > best.figure) best = std::move(o2);
    }
  }
  return best;
}

// The opening back onto the whole layout: local nodes and quads in the order
// of the whole one, then the new node and the new quad.
void apply_opening(LayoutMesh& m, const Opening& best, LayoutOpeningReport& report) {
  const LocalLayout& l = best.local;
  const int added = static_cast<int>(m.size());
  auto global = [&](int v) { return v < static_cast<int>(l.node.size()) ? l.node[v] : added; };
  m.x.push_back(Eigen::Vector2d::Zero()), m.ring.push_back(-1), m.arc.push_back(0.0);
  for (std::size_t q = 0; q < l.quad.size(); ++q)
    for (int j = 0; j < 4; ++j) m.quads[l.quad[q]][j] = global(l.mesh.quads[q][j]);
  std::array<int, 4> fresh;
  for (int j = 0; j < 4; ++j) fresh[j] = global(l.mesh.quads.back()[j]);
  m.quads.push_back(fresh);
  for (const int v : best.free) {
    const int g = global(v);
    m.x[g] = l.mesh.x[v], m.arc[g] = l.mesh.arc[v];
    report.moved.push_back(g);
  }
  ++report.kept;
}

}  // namespace

LayoutOpeningReport open_wide_ring_corners(LayoutMesh& m, const LayoutQuality& Q, const LayoutAdmissible& admissible,
                                           const LayoutOpeningOptions& o) {
  LayoutOpeningReport report;
  const LayoutOptimizationOptions lo{.max_sweeps = o.local_sweeps, .cancel = o.cancel};
  LayoutTopology t(m);
  std::vector<std::pair<double, int>> wide;  // widest first
  for (int n = 0; n < static_cast<int>(m.size()); ++n)
    if (m.ring[n] >= 0) {
      const double w = widest_corner(m, t, Q, n);
      if (w > o.wide_corner_degrees) wide.push_back({-w, n});
    }
  std::sort(wide.begin(), wide.end());
  // The corners in order, in batches whose tries read disjoint local layouts:
  // each batch's tries run on the pool's threads and are applied in order;
  // the result is that of trying them one by one (an opening writes only
  // inside its local layout, and appends a node and a quad that no other
  // try of the batch reads). A batch ends before the first corner whose
  // local layout meets one of the batch's: corners past it may not go first,
  // for the nodes and quads an opening appends are numbered in order.
  const std::size_t max_batch = std::max<std::size_t>(1, o.max_batch);
  std::vector<char> reached;
  for (std::size_t i = 0; i < wide.size();) {
    throw_if_cancelled(o.cancel);
    reached.assign(m.size(), 0);
    std::vector<std::size_t> batch;
    std::vector<LocalLayout> bases;
    for (; i < wide.size() && batch.size() < max_batch; ++i) {
      const int n = wide[i].second;
      // The local layout of everything a try reads: the nodes within three
      // rings of n hold the quads of every node a try may move.
      LocalLayout base = local_layout(m, t, rings_around(m, t, {n}, 3));
      if (std::any_of(base.node.begin(), base.node.end(), [&](int v) { return reached[v] != 0; })) break;
      // (An earlier opening mended it: nothing to try.)
      if (widest_corner(m, t, Q, n) <= o.wide_corner_degrees) continue;
      for (const int v : base.node) reached[v] = 1;
      batch.push_back(i);
      bases.push_back(std::move(base));
    }
    std::vector<Opening> best(batch.size());
    std::vector<std::size_t> tried(batch.size(), 0);
    detail::parallel_items(batch.size(), detail::pool_threads(), [&](std::size_t b) {
      const int n = wide[batch[b]].second;
      best[b] = best_opening(bases[b], LocalLayout::local(bases[b].node, n), Q, admissible, lo, tried[b]);
    });
    bool changed = false;
    for (std::size_t b = 0; b < batch.size(); ++b) {
      report.tried += tried[b];
      if (!std::isfinite(best[b].figure)) continue;
      apply_opening(m, best[b], report);
      changed = true;
    }
    if (changed) t = LayoutTopology(m);
  }
  std::sort(report.moved.begin(), report.moved.end());
  report.moved.erase(std::unique(report.moved.begin(), report.moved.end()), report.moved.end());
  return report;
}

}  // namespace tspline
