#include "tspline/layout/layout_optimizer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "layout_local.h"
#include "tspline/boundary/plane.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/layout/layout_energy.h"

namespace tspline {
namespace {

// Ring node n slid along its ring, between its two ring neighbours, to where
// `local` (its energy, or a sum at least its second argument where the energy
// is not below that) is least: every ring vertex in reach (where the corner
// angles jump; the nearest max_ring_vertices), a uniform grid, then a local
// refinement. `best` is the energy where it stands on entry, the energy
// where it ends on return.
template <class Local, class Allowed>
void slide_ring_node(LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n, const Local& local,
                     const Allowed& allowed, const LayoutOptimizationOptions& o, double& best) {
  const std::size_t nn = static_cast<std::size_t>(n);
  const int r = m.ring[n];
  const RingCurve& c = Q.rings().curves[r];
  const double d = Q.rings().direction(r), L = c.length();
  double back = -1.0, ahead = -1.0;  // arc lengths to the ring neighbours
  for (const auto& [q, j] : t.corners_of(n)) {
    if (t.on_ring(q, j)) ahead = Q.side_length(m, t, q, j);
    if (t.on_ring(q, (j + 3) % 4)) back = Q.side_length(m, t, q, (j + 3) % 4);
  }
  if (!(back > 0.0 && ahead > 0.0)) return;
  const double s0 = m.arc[nn];
  const Eigen::Vector2d x0 = m.x[nn];
  // Candidates u in (-0.9 back, 0.9 ahead): the node at arc s0 + d u.
  const double lo = -0.9 * back, hi = 0.9 * ahead;
  std::vector<double> cand;
  for (int k = 0; k <= o.ring_samples; ++k) cand.push_back(lo + (hi - lo) * k / o.ring_samples);
  {
    std::vector<double> verts;
    const double from = d > 0.0 ? s0 + lo : s0 - hi;  // forward arc range [from, from + hi - lo]
    std::size_t i = c.first_vertex_after(from);
    double base = std::fmod(from, L);
    if (base < 0.0) base += L;
    const double shift = from - base;  // unwrapped arcs: c.arc(i) + shift (+ L past the end)
    for (std::size_t k = 0; k < c.size(); ++k, ++i) {
      const double sv = (i < c.size() ? c.arc(i) : c.arc(i - c.size()) + L) + shift;
      if (sv >= from + (hi - lo)) break;
      verts.push_back(d > 0.0 ? sv - s0 : s0 - sv);
    }
    std::sort(verts.begin(), verts.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
    if (verts.size() > static_cast<std::size_t>(o.max_ring_vertices)) verts.resize(o.max_ring_vertices);
    cand.insert(cand.end(), verts.begin(), verts.end());
  }
  // Never a hair's breadth from a vertex (the patch polygon would have a needle edge).
  const double snap = 0.02 * std::min(back, ahead);
  auto place = [&](double u) {
    double sv = std::fmod(s0 + d * u, L);
    if (sv < 0.0) sv += L;
    sv = c.snap_to_vertex(sv, snap);
    m.arc[nn] = sv;
    m.x[nn] = c.point(sv);
  };
  double best_u = 0.0;
  for (const double u : cand) {
    if (!(u > lo - 1e-12 && u < hi + 1e-12) || u == 0.0) continue;
    place(u);
    const double f = local(n, best);
    if (f < best && allowed()) best = f, best_u = u;
  }
  // Local refinement around the best (the energy is smooth between vertices).
  double h = (hi - lo) / o.ring_samples;
  for (int it = 0; it < 12; ++it, h *= 0.5)
    for (const double u : {best_u - h, best_u + h}) {
      if (!(u > lo && u < hi)) continue;
      place(u);
      const double f = local(n, best);
      if (f < best && allowed()) best = f, best_u = u;
    }
  if (best_u == 0.0) m.arc[nn] = s0, m.x[nn] = x0;
  else place(best_u);
}

// The pattern search's eight directions.
const std::array<Eigen::Vector2d, 8> kDirections = [] {
  std::array<Eigen::Vector2d, 8> d;
  for (int k = 0; k < 8; ++k) {
    const double a = k * std::numbers::pi / 4.0;
    d[k] = Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  return d;
}();

// What one node's move in a sweep did.
struct NodeMove {
  bool moved = false;
  double gain = 0.0;  ///< its energy's relative fall
};

// update(k) for every node order[k], with the result of running them one by
// one in that order, but in batches on the pool's threads. A node's move
// reads only the nodes of the quads around it and writes only its own place
// (and its own pattern-search step), so two nodes that share no quad give
// the same result in either order. A batch takes the nodes in order that
// share no quad with an earlier node not yet run (in the batch, or waiting
// for a later one); nodes past one that waits may join it.
template <class Update>
void sweep_in_batches(const LayoutMesh& m, const LayoutTopology& t, const std::vector<int>& order,
                      std::vector<char>& reached, bool in_batches, const Update& update) {
  constexpr std::size_t min_parallel = 64;
  if (!in_batches || order.size() < min_parallel || detail::pool_threads() < 2) {
    for (std::size_t k = 0; k < order.size(); ++k) update(k);
    return;
  }
  std::vector<char> done(order.size(), 0);
  std::vector<std::size_t> batch;
  std::vector<int> marked;
  for (std::size_t i = 0; i < order.size();) {
    batch.clear();
    for (std::size_t k = i; k < order.size(); ++k) {
      if (done[k]) continue;
      const int n = order[k];
      // reached: the nodes that share a quad with an earlier node not yet run.
      const bool clear = !reached[n];
      for (const auto& [q, j] : t.corners_of(n))
        for (const int v : m.quads[q])
          if (!reached[v]) reached[v] = 1, marked.push_back(v);
      if (!clear) continue;
      done[k] = 1;
      batch.push_back(k);
    }
    for (const int v : marked) reached[v] = 0;
    marked.clear();
    while (i < order.size() && done[i]) ++i;
    detail::parallel_items(
        batch.size(), detail::pool_threads(), [&](std::size_t b) { update(batch[b]); }, 16);
  }
}

}  // namespace

LayoutCornerQuality worst_layout_quality(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& q) {
  LayoutCornerQuality w{1.0, 1.0};
  for (std::size_t k = 0; k < m.quads.size(); ++k) {
    const LayoutCornerQuality c = q.quad(m, t, static_cast<int>(k));
    w.mean_ratio = std::min(w.mean_ratio, c.mean_ratio);
    w.scaled_jacobian = std::min(w.scaled_jacobian, c.scaled_jacobian);
  }
  return w;
}

LayoutOptimizationReport optimize_layout_nodes(LayoutMesh& m, const LayoutQuality& Q,
                                               const LayoutAdmissible& admissible, const std::vector<int>& active_in,
                                               const LayoutOptimizationOptions& o) {
  const LayoutTopology t(m);
  LayoutOptimizationReport report;
  const std::size_t n_nodes = m.size();
  std::vector<int> active = active_in;
  if (active.empty())
    for (std::size_t n = 0; n < n_nodes; ++n) active.push_back(static_cast<int>(n));
  // The quads around the active nodes: where the figures are taken.
  std::vector<int> region;
  {
    std::vector<char> seen(m.quads.size(), 0);
    for (const int n : active)
      for (const auto& [q, j] : t.corners_of(n))
        if (!seen[q]) seen[q] = 1, region.push_back(q);
  }
  // The worst figures over the region, on the pool's threads (a minimum: the
  // same in any order; Newfoundland's layout: 5,000 quads before every sweep).
  const int slots = detail::pool_threads();
  auto worst = [&]() {
    std::vector<LayoutCornerQuality> part(static_cast<std::size_t>(slots), LayoutCornerQuality{1.0, 1.0});
    detail::parallel_ranges(region.size(), slots, [&](std::size_t b, std::size_t e, int slot) {
      LayoutCornerQuality& w = part[static_cast<std::size_t>(slot)];
      for (std::size_t i = b; i < e; ++i) {
        const LayoutCornerQuality c = Q.quad(m, t, region[i]);
        w.mean_ratio = std::min(w.mean_ratio, c.mean_ratio);
        w.scaled_jacobian = std::min(w.scaled_jacobian, c.scaled_jacobian);
      }
    });
    LayoutCornerQuality w{1.0, 1.0};
    for (const LayoutCornerQuality& c : part) {
      w.mean_ratio = std::min(w.mean_ratio, c.mean_ratio);
      w.scaled_jacobian = std::min(w.scaled_jacobian, c.scaled_jacobian);
    }
    return w;
  };
  report.before = worst();
  // Whether node n may stay where it was just moved: where the caller's check
  // held before the move, it must hold after it (a node whose cuts already
  // cross a ring may move anywhere its energy falls: the check would otherwise
  // pin it where it is wrong); with keep_patch_corners_in_range, no more
  // patch corners of its quads out of range than before.
  auto move_check = [&](int n) {
    const bool was_admissible = admissible(m, t, n);
    const int rejected = o.keep_patch_corners_in_range ? layout_local::rejected_corners(m, t, Q, {n}) : 0;
    return [&m, &t, &Q, &admissible, &o, n, was_admissible, rejected]() {
      return (!was_admissible || admissible(m, t, n)) &&
             (!o.keep_patch_corners_in_range || layout_local::rejected_corners(m, t, Q, {n}) <= rejected);
    };
  };
  // Untangling first: while corners are inverted, eps follows the worst of
  // them (Garanzha et al. 2021: eps above the most negative det keeps the
  // energy moderate, so that every corner can move), with the plain sum (p = 1);
  // then eps = 1e-4 and p = power, close to the worst corner.
  double p = o.power, eps_rel = 1e-4;
  bool barrier = false;
  auto local = [&](int n) { return layout_node_energy(m, t, Q, n, p, eps_rel, barrier); };
  auto worst_sin = [&]() {
    std::vector<double> part(static_cast<std::size_t>(slots), 1.0);
    detail::parallel_ranges(region.size(), slots, [&](std::size_t b, std::size_t e, int slot) {
      double& w = part[static_cast<std::size_t>(slot)];
      for (std::size_t i = b; i < e; ++i)
        for (int j = 0; j < 4; ++j) w = std::min(w, Q.corner(m, t, region[i], j).scaled_jacobian);
    });
    return *std::min_element(part.begin(), part.end());
  };
  // Pattern-search steps of the inner nodes, kept between sweeps.
  std::vector<double> step(n_nodes, 0.0);
  for (const int n : active) {
    double shortest = std::numeric_limits<double>::infinity();
    for (const auto& [q, j] : t.corners_of(static_cast<int>(n)))
      for (const int k : {1, 3}) shortest = std::min(shortest, (m.x[m.quads[q][(j + k) % 4]] - m.x[n]).norm());
    step[n] = std::isfinite(shortest) ? 0.2 * shortest : 0.0;
  }
  const std::vector<double> initial_step = step;
  // The quads around each node that are poor (figure below `busy`): after the
  // first sweeps of the quality phase, only their nodes and those nodes'
  // neighbours move (elsewhere the worst corner is far away).
  constexpr double busy = 0.6;
  std::vector<int> moving = active;
  auto refresh_moving = [&]() {
    std::vector<char> on(n_nodes, 0);
    for (const int q : region) {
      LayoutCornerQuality c = Q.quad(m, t, q);
      double f = c.mean_ratio;
      for (int j = 0; j < 4; ++j) f = std::min(f, Q.side_shape(m, t, q, j));
      if (f >= busy) continue;
      for (const int v : m.quads[q])
        for (const auto& [q2, j2] : t.corners_of(v))
          for (const int w2 : m.quads[q2]) on[w2] = 1;
    }
    moving.clear();
    for (const int n : active)
      if (on[n]) moving.push_back(n);
  };
  std::vector<int> order;       // the nodes moved in a sweep, in order
  std::vector<NodeMove> moves;  // and what their moves did
  std::vector<char> reached(n_nodes, 0);
  bool untangling = false;
  int quality_sweeps = 0;
  double best_worst = -2.0;  // the worst J_r of the quality sweeps, and when it last rose
  int best_sweep = 0;
  double worst_tangled = -2.0;  // the worst corner of the tangled sweeps, and when it last rose
  int last_rise = 0;
  for (int sweep = 0; sweep < o.max_sweeps; ++sweep) {
    throw_if_cancelled(o.cancel);
    const double w = worst_sin();
    const bool tangled = w <= 0.0;
    if (tangled) {
      // Untangling that no longer raises the worst corner is stuck (a
      // topological defect, a flat single-quad corner: the caller's business).
      if (w > worst_tangled + 1e-6) worst_tangled = w, last_rise = sweep;
      if (sweep - last_rise >= 6) break;
    }
    p = tangled ? 1.0 : o.power;
    barrier = !tangled;
    eps_rel = tangled ? std::max(1e-4, 2.0 * -w) : 1e-4;
    if (untangling && !tangled)  // the steps were made for the other energy
      for (const int n : active) step[n] = std::max(step[n], 0.25 * initial_step[n]);
    untangling = tangled;
    if (!tangled && ++quality_sweeps == 3) refresh_moving();
    if (!tangled && quality_sweeps > 3 && quality_sweeps % 5 == 0) refresh_moving();
    // One node's move: whether it moved and its relative gain.
    auto update = [&](int n) -> NodeMove {
      const std::size_t nn = static_cast<std::size_t>(n);
      const double f0 = local(n);
      // Only the terms that move with n are evaluated (layout_moving_energy):
      // the energy differs from local(n) by a constant. Where that part is
      // not finite, the whole energy is.
      const LayoutMovingEnergy moving_part(m, t, Q, n, p, eps_rel, barrier);
      const double v0 = moving_part();
      if (!std::isfinite(f0) && std::isfinite(v0)) return {};  // infinite wherever n goes
      const bool incremental = std::isfinite(f0) && std::isfinite(v0);
      // (A place's energy only counts if it beats the best so far: its sum may stop there.)
      auto energy = [&](int v, double best_so_far) {
        return incremental ? moving_part(best_so_far) : local(v);
      };
      double best_v = incremental ? v0 : f0;
      const auto allowed = move_check(n);
      if (m.ring[n] < 0) {
        // Inner node: pattern search, the best of eight directions per step.
        for (int it = 0; it < 4 && step[nn] > 0.0; ++it) {
          const Eigen::Vector2d start = m.x[nn];
          Eigen::Vector2d best_x = start;
          for (int k = 0; k < 8; ++k) {
            m.x[nn] = start + step[nn] * kDirections[k];
            const double f = energy(n, best_v);
            if (f < best_v && allowed()) best_v = f, best_x = m.x[nn];
          }
          m.x[nn] = best_x;
          if (best_x == start)
            step[nn] *= 0.5;
          else
            step[nn] *= 1.5;
        }
      } else {
        slide_ring_node(m, t, Q, n, energy, allowed, o, best_v);
      }
      const double best = incremental ? f0 - (v0 - best_v) : best_v;
      if (!(best < f0)) return {};
      return {true, (f0 - best) / f0};
    };
    // The nodes that may move this sweep, in order. While the layout is
    // tangled the rings stay where they are: sliding a ring node across a fold
    // only drags the fold along the coast; but a ring node whose own corner
    // is inverted slides (untangle_ring_corners).
    order.clear();
    auto own_corner_inverted = [&](int n) {
      for (const auto& [q, j] : t.corners_of(n))
        if (Q.corner(m, t, q, j).scaled_jacobian <= 0.0) return true;
      return false;
    };
    for (const int n : (tangled || quality_sweeps < 3 ? active : moving))
      if (t.valence(n) != 0 &&
          !(tangled && m.ring[n] >= 0 && !(o.untangle_ring_corners && own_corner_inverted(n))))
        order.push_back(n);
    moves.assign(order.size(), NodeMove{});
    sweep_in_batches(m, t, order, reached, o.in_batches, [&](std::size_t k) { moves[k] = update(order[k]); });
    double gain = 0.0;
    for (const NodeMove& mv : moves)
      if (mv.moved) ++report.moves, gain = std::max(gain, mv.gain);
    report.sweeps = sweep + 1;
    if (gain < o.tolerance && !tangled) break;
    if (!tangled) {
      // The worst corner is what counts: stop when it has not risen for a while.
      const double f = worst().mean_ratio;
      if (f > best_worst + 1e-3 * std::abs(best_worst)) best_worst = f, best_sweep = sweep;
      if (sweep - best_sweep >= o.stall_sweeps) break;
    }
  }
  report.after = worst();
  return report;
}

LayoutAdmissible admissible_in(const RingGeometry& geometry, double tol) {
  return [&geometry, tol](const LayoutMesh& m, const LayoutTopology& t, int n) {
    if (m.ring[n] < 0 && !geometry.inside(m.x[n])) return false;
    for (const auto& [q, j] : t.corners_of(n))
      for (const int k : {1, 3}) {
        if (t.on_ring(q, k == 1 ? j : (j + 3) % 4)) continue;
        const int other = m.quads[q][(j + k) % 4];
        if (!geometry.admits_cut(m.x[n], m.x[other], m.ring[n] >= 0, m.ring[other] >= 0, tol)) return false;
      }
    return true;
  };
}

}  // namespace tspline
