#include "tspline/layout/quad_layout.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <set>
#include <unordered_map>
#include <sstream>

#include "tspline/errors.h"
#include "tspline/layout/layout_kstar.h"
#include "tspline/layout/layout_optimizer.h"
#include "tspline/layout/layout_quality.h"
#include "tspline/layout/layout_topology.h"
#include "tspline/layout/quad_mesher.h"
#include "tspline/layout/ring_geometry.h"
#include "toolkit/timing.h"
#include "tspline/boundary/plane.h"

namespace tspline {
namespace {


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

bool debugging() { return std::getenv("TSPLINE_LAYOUT_DEBUG") != nullptr; }

// Debugging: the worst quads, corner by corner.
void print_worst(const LayoutMesh& m, const LayoutQuality& Q, int count) {
  const LayoutTopology t(m);
  std::vector<std::pair<double, int>> f;
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    f.push_back({layout_quad_figure(m, t, Q, static_cast<int>(q)), static_cast<int>(q)});
  std::sort(f.begin(), f.end());
  for (int k = 0; k < count && k < static_cast<int>(f.size()); ++k) {
    const int q = f[k].second;
    std::fprintf(stderr, "  worst quad %d (%.3g):", q, f[k].first);
    for (int j = 0; j < 4; ++j) {
      const int v = m.quads[q][j];
      const LayoutCornerQuality c = Q.corner(m, t, q, j);
      std::fprintf(stderr, " [node %d ring %d (%.4f, %.4f) valence %zu: J_r %.3g SJ %.3g; side kinks %.3g shape %.3g]", v,
                   m.ring[v], m.x[v].x(), m.x[v].y(), t.valence(v), c.mean_ratio, c.scaled_jacobian,
                   Q.side_kinks(m, t, q, j), Q.side_shape(m, t, q, j));
    }
    std::fprintf(stderr, "\n");
  }
}

// Seconds since the last call (debugging output).
double lap() {
  static thread_local auto last = std::chrono::steady_clock::now();
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - last).count();
  last = now;
  return s;
}

void report_optimization(const LayoutOptimizationReport& rep, QuadLayoutStats& st) {
  st.optimization_sweeps += rep.sweeps;
  if (debugging())
    std::fprintf(stderr, "layout optimization: J_r %.4g -> %.4g, SJ %.4g -> %.4g, %d sweeps, %zu moves, %.2f s\n",
                 rep.before.mean_ratio, rep.after.mean_ratio, rep.before.scaled_jacobian, rep.after.scaled_jacobian,
                 rep.sweeps, rep.moves, lap());
}

// The layout mesh optimized for its patch maps (level 0: as the mesher made
// it; 1: node optimization; 2: and edge rotations where quads stay poor):
//  1. K* untangling of the inner nodes, then a short node optimization;
//  2. edge rotations, which also walk flat single-quad ring corners away;
//  3. rings that still have a flat single-quad corner are pillowed;
//  4. the node optimization in full, then rotations and the optimization
//     again while rotations are kept.
// `start` becomes the mesh the checks fall back to (the mesher's nodes, after
// any pillowing).
void optimize_layout(LayoutMesh& m, LayoutMesh& start, const LayoutRings& R, const LayoutQuality& Q,
                     const LayoutAdmissible& admissible, int level, QuadLayoutStats& st,
                     const std::atomic<bool>* cancel) {
  st.rotations = 0;
  st.openings = 0;
  st.optimization_sweeps = 0;
  st.pillowed_rings = 0;
  // Every sweep and rotation batch checks the cancel flag.
  LayoutOptimizationOptions full;
  full.cancel = cancel;
  LayoutRotationOptions rotation;
  rotation.cancel = cancel;
  auto rotate = [&]() {
    LayoutRotationReport rr = rotate_layout_edges(m, Q, admissible, rotation);
    st.rotations += rr.kept;
    if (debugging()) std::fprintf(stderr, "layout rotations: %zu tried, %zu kept, %.2f s\n", rr.tried, rr.kept, lap());
    return rr;
  };
  if (debugging()) lap();
  if (level >= 1) {
    smooth_layout_kstar(m, R);
    if (debugging()) std::fprintf(stderr, "layout K*: %.2f s\n", lap());
    LayoutOptimizationOptions quick = full;
    quick.max_sweeps = 8;
    report_optimization(optimize_layout_nodes(m, Q, admissible, {}, quick), st);
    if (level >= 2) rotate();
  }
  const std::vector<char> flat = rings_with_flat_corners(m, Q);
  st.pillowed_rings = static_cast<std::size_t>(std::count(flat.begin(), flat.end(), 1));
  if (st.pillowed_rings > 0) {
    if (level == 0) m = start;
    pillow_rings(m, flat);
    start = m;
    if (level >= 1) smooth_layout_kstar(m, R);
  }
  if (level < 1) return;
  report_optimization(optimize_layout_nodes(m, Q, admissible, {}, full), st);
  if (level >= 2) {
    // Wide ring corners that rotations cannot split (valence-3 neighbours).
    LayoutOpeningOptions opening;
    opening.cancel = cancel;
    const LayoutOpeningReport op = open_wide_ring_corners(m, Q, admissible, opening);
    st.openings = op.kept;
    if (debugging()) std::fprintf(stderr, "layout openings: %zu tried, %zu kept, %.2f s\n", op.tried, op.kept, lap());
    if (op.kept > 0) report_optimization(optimize_layout_nodes(m, Q, admissible, op.moved, full), st);
  }
  for (int pass = 0; pass < 2 && level >= 2; ++pass) {
    // Around the rotations kept (the rest of the layout is as optimized as it gets).
    const LayoutRotationReport rr = rotate();
    if (rr.kept == 0) break;
    report_optimization(optimize_layout_nodes(m, Q, admissible, rr.moved, full), st);
  }
  if (debugging()) print_worst(m, Q, 4);
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
  s.precision(3);
  s << ", worst corner J_r " << stats.corner_mean_ratio << " scaled Jacobian " << stats.corner_scaled_jacobian
    << (stats.optimization_level == 2   ? ""
        : stats.optimization_level == 1 ? " (no edge rotations: they broke it)"
                                        : " (nodes not optimized: that broke it)");
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

  LayoutRings R;
  R.curves.emplace_back(d.outer.vertices);
  for (const Polygon& p : d.holes) R.curves.emplace_back(p.vertices);
  const std::vector<RingCurve>& rings = R.curves;
  RingNodeOptions no = o.nodes;
  if (!(no.min_size > 0.0)) no.min_size = so.min_size;
  std::vector<std::vector<double>> nodes;
  for (const RingCurve& r : rings) nodes.push_back(ring_nodes(r, no, piece_size));

  const RingGeometry geometry = RingGeometry::of_rings(rings);
  const double tol = 1e-9 * diam;
  const LayoutQuality quality(R);
  // A node may stay where the optimizer moved it: inside the domain, its cuts off the rings.
  const LayoutAdmissible admissible = admissible_in(geometry, tol);

  auto note = [&](const std::string& text) {
    if (o.progress) o.progress(text);
  };
  QuadLayout out;
  int meshes = 0;  // made by the mesher (rounds that only add ring nodes make none)
  int level = 2;
  int repairs = 0;  // rounds that added nodes (dropping an optimization level is not one)
  std::vector<Eigen::Vector2d> repaired_at;  // where a rejected layout got a ring node more
  for (int round = 0;; ++round) {
    throw_if_cancelled(o.cancel);
    if (repairs > o.max_repair_rounds)
      throw NumericalError("no quad layout found: the layout still crosses the boundary after " +
                           std::to_string(o.max_repair_rounds) + " rounds of adding nodes");
    std::vector<std::set<std::size_t>> to_split(rings.size());
    auto marked = [&]() {
      std::size_t k = 0;
      for (const auto& pieces : to_split) k += pieces.size();
      return k;
    };
    auto split_marked = [&]() {
      bool any = false;
      for (std::size_t r = 0; r < rings.size(); ++r)
        // From the last piece down: indices of earlier pieces stay valid.
        for (auto it = to_split[r].rbegin(); it != to_split[r].rend(); ++it) {
          split_piece(rings[r], nodes[r], *it);
          any = true;
        }
      return any;
    };
    auto mark_nearest_piece = [&](const Eigen::Vector2d& p) {
      const RingGeometry::Edge& e = geometry.edge(geometry.nearest(p));
      to_split[e.ring].insert(piece_of(nodes[e.ring], rings[e.ring].arc(e.index)));
    };
    // The straight rings (chords between the nodes) must be simple and
    // disjoint, and no chord may cut off a piece of another ring.
    std::vector<std::vector<Eigen::Vector2d>> straight(rings.size());
    std::vector<RingGeometry::Edge> chords;
    for (std::size_t r = 0; r < rings.size(); ++r) {
      for (double s : nodes[r]) straight[r].push_back(rings[r].point(s));
      for (std::size_t k = 0; k < straight[r].size(); ++k)
        chords.push_back({straight[r][k], straight[r][(k + 1) % straight[r].size()], static_cast<int>(r), k});
    }
    {
      const RingGeometry cg(chords, lo, hi);
      for (std::size_t c = 0; c < chords.size(); ++c) {
        const auto& e = chords[c];
        for (int o2 : cg.near(e.a.cwiseMin(e.b), e.a.cwiseMax(e.b))) {
          if (o2 <= static_cast<int>(c)) continue;
          const auto& f = cg.edge(o2);
          const std::size_t n = straight[e.ring].size();
          const bool adjacent = f.ring == e.ring && (f.index == (e.index + 1) % n || e.index == (f.index + 1) % n);
          if (adjacent && n > 2) continue;
          if (segments_intersect(e.a, e.b, f.a, f.b)) to_split[e.ring].insert(e.index), to_split[f.ring].insert(f.index);
        }
      }
      for (const auto& e : chords)
        for (int g : geometry.near(e.a.cwiseMin(e.b), e.a.cwiseMax(e.b))) {
          const auto& f = geometry.edge(g);
          if (f.ring != e.ring && segments_intersect(e.a, e.b, f.a, f.b)) {
            to_split[e.ring].insert(e.index);
            to_split[f.ring].insert(piece_of(nodes[f.ring], rings[f.ring].arc(f.index)));
          }
        }
    }
    // At a sharp tip of the coast (the domain's angle there below 60 or above
    // 300 degrees on the scale of a fifth of the pieces next to the node) the
    // straight ring must be as sharp: the chord to a neighbour and the ring's
    // own direction within 35 degrees; else the mesher sees a blunt corner where
    // the coast has a tip, and gives it too few quads (a reflex tip of 340
    // degrees split in two corners of 170 degrees).
    for (std::size_t r = 0; r < rings.size(); ++r) {
      const std::size_t n = nodes[r].size();
      if (n < 3) continue;
      const double L = rings[r].length();
      for (std::size_t k = 0; k < n; ++k) {
        const double s = nodes[r][k];
        const Eigen::Vector2d p = rings[r].point(s);
        double len[2];
        Eigen::Vector2d near[2], chord[2];
        for (const int side : {0, 1}) {
          const std::size_t other = side == 0 ? (k + 1) % n : (k + n - 1) % n;
          len[side] = side == 0 ? nodes[r][other] - s : s - nodes[r][other];
          if (len[side] <= 0.0) len[side] += L;
          chord[side] = straight[r][other] - p;
          near[side] = rings[r].point(s + (side == 0 ? 1.0 : -1.0) * 0.2 * len[side]) - p;
        }
        // The domain's angle at the node from the forward to the backward direction
        // (the domain on the left of the outer ring, on the right of holes).
        double phi = std::atan2(cross(near[0], near[1]), near[0].dot(near[1]));
        if (R.direction(static_cast<int>(r)) < 0.0) phi = -phi;
        if (phi < 0.0) phi += 2.0 * std::numbers::pi;
        if (phi > std::numbers::pi / 3.0 && phi < 5.0 * std::numbers::pi / 3.0) continue;
        for (const int side : {0, 1}) {
          const double angle = std::abs(std::atan2(cross(chord[side], near[side]), chord[side].dot(near[side])));
          if (angle > 35.0 * std::numbers::pi / 180.0 && len[side] > 2.0 * no.min_size)
            to_split[r].insert(side == 0 ? k : (k + n - 1) % n);
        }
      }
    }
    if (split_marked()) {
      out.stats.repair_rounds = ++repairs;
      continue;
    }

    PlanarQuadMesh qm;
    try {
      qm = quad_mesh(straight, h);
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
      note("mesh " + std::to_string(meshes + 1) + ": the quad mesher lost a piece of ring " + std::to_string(r) +
           "; 3 ring nodes more there, meshing again");
      split_marked();
      out.stats.repair_rounds = ++repairs;
      continue;
    }
    // The mesh must tile the straight domain: every edge used by two quads in
    // opposite directions, or by one quad along a ring (between nodes of that
    // ring). Gmsh can mesh a sliver inside a hole, or lose a ring node's curve
    // where straight pieces nearly touch: more ring nodes there, and again.
    {
      std::unordered_map<unsigned long long, int> directed;
      auto key = [](int a, int b) {
        return (static_cast<unsigned long long>(static_cast<unsigned>(a)) << 32) | static_cast<unsigned>(b);
      };
      for (const auto& q : qm.quads)
        for (int j = 0; j < 4; ++j) ++directed[key(q[j], q[(j + 1) % 4])];
      bool broken = false;
      for (const auto& q : qm.quads)
        for (int j = 0; j < 4; ++j) {
          const int a = q[j], b = q[(j + 1) % 4];
          const bool twice = directed[key(a, b)] > 1;
          const bool boundary = directed.find(key(b, a)) == directed.end();
          if (twice || (boundary && !(qm.ring[a] >= 0 && qm.ring[a] == qm.ring[b]))) {
            mark_nearest_piece(0.5 * (qm.nodes[a] + qm.nodes[b]));
            broken = true;
          }
        }
      if (broken && split_marked()) {
        out.stats.repair_rounds = ++repairs;
        continue;
      }
      if (broken) throw NumericalError("the quad mesher's quadrilaterals do not tile the domain");
    }
    // The mesh with its boundary nodes on the true rings.
    LayoutMesh m{qm.nodes, qm.ring, std::vector<double>(qm.nodes.size(), 0.0), qm.quads};
    for (std::size_t n = 0; n < m.size(); ++n) {
      if (m.ring[n] < 0) continue;
      const auto& nr = nodes[m.ring[n]];
      const double L = rings[m.ring[n]].length();
      const std::size_t k = static_cast<std::size_t>(qm.segment[n]);
      const double a = nr[k], b = k + 1 < nr.size() ? nr[k + 1] : nr.front() + L;
      m.arc[n] = rings[m.ring[n]].snap_to_vertex(a + qm.t[n] * (b - a), 0.01 * (b - a));
      m.x[n] = rings[m.ring[n]].point(m.arc[n]);
    }
    LayoutMesh start = m;  // the mesher's nodes, on the true rings
    ++meshes;
    note("mesh " + std::to_string(meshes) + ": " + std::to_string(m.quads.size()) + " quads from the mesher; optimizing them" +
         (level == 2 ? "" : " without edge rotations"));
    const auto t_opt = std::chrono::steady_clock::now();
    optimize_layout(m, start, R, quality, admissible, level, out.stats, o.cancel);
    if (debugging())
      std::fprintf(stderr, "layout round %d: mesh %zu quads at %.2f s, optimized in %.2f s\n", round, m.quads.size(),
                   std::chrono::duration<double>(t_opt - t0).count(),
                   toolkit::seconds_since(t_opt));

    // Checks on the true geometry: inner nodes inside, cuts off the rings. The
    // nodes involved in a violation go back where the mesher put them (with the
    // quads of the mesher, if rotations changed them); what still fails gets
    // ring nodes more near it, and the mesh is made again.
    auto violations = [&](const LayoutMesh& lm, bool mark) {
      std::set<int> involved;
      const LayoutTopology t(lm);
      for (std::size_t n = 0; n < lm.size(); ++n)
        if (lm.ring[n] < 0 && t.valence(static_cast<int>(n)) > 0 && !geometry.inside(lm.x[n])) {
          involved.insert(static_cast<int>(n));
          if (mark) mark_nearest_piece(lm.x[n]);
        }
      for (std::size_t q = 0; q < lm.quads.size(); ++q)
        for (int j = 0; j < 4; ++j) {
          const int a = lm.quads[q][j], b = lm.quads[q][(j + 1) % 4];
          if (t.on_ring(static_cast<int>(q), j) || a > b) continue;  // each cut once
          const int g = geometry.crossing(lm.x[a], lm.x[b], lm.ring[a] >= 0, lm.ring[b] >= 0, tol);
          if (g < 0) {
            // Between two ring nodes, wholly outside (geometry.admits_cut).
            if (geometry.admits_cut(lm.x[a], lm.x[b], lm.ring[a] >= 0, lm.ring[b] >= 0, tol)) continue;
            involved.insert(a), involved.insert(b);
            if (mark) mark_nearest_piece(0.5 * (lm.x[a] + lm.x[b]));
            continue;
          }
          involved.insert(a), involved.insert(b);
          if (mark) {
            const RingGeometry::Edge& f = geometry.edge(g);
            to_split[f.ring].insert(piece_of(nodes[f.ring], rings[f.ring].arc(f.index)));
          }
        }
      return involved;
    };
    if (debugging())
      std::fprintf(stderr, "layout round %d: %zu nodes in violations at the start, %zu after optimization\n", round,
                   violations(start, false).size(), violations(m, false).size());
    if (!violations(m, false).empty() && m.quads != start.quads) m = start;  // rotations undone
    for (int pass = 0; pass < 3; ++pass) {
      bool changed = false;
      for (int n : violations(m, false))
        if (m.x[n] != start.x[n]) m.x[n] = start.x[n], m.arc[n] = start.arc[n], changed = true;
      if (!changed) break;
    }
    if (debugging()) std::fprintf(stderr, "  %zu nodes still in violation\n", violations(m, false).size());
    {
      const std::size_t bad = violations(m, true).size();
      if (bad > 0)
        note("mesh " + std::to_string(meshes) + ": " + std::to_string(bad) +
             " node(s) outside the domain or with cuts across its boundary; " + std::to_string(marked()) +
             " ring node(s) more there, meshing again");
    }
    if (split_marked()) {
      out.stats.repair_rounds = ++repairs;
      out.stats.optimization_level = level = 2;  // the new mesh is optimized in full
      continue;
    }

    // The layout: inner edges are cuts, ring nodes of one quad are ring corners.
    const LayoutTopology t(m);
    std::vector<Cut> cuts;
    out.ring_corners.clear();
    for (std::size_t q = 0; q < m.quads.size(); ++q)
      for (int j = 0; j < 4; ++j) {
        const int a = m.quads[q][j], b = m.quads[q][(j + 1) % 4];
        if (!t.on_ring(static_cast<int>(q), j) && a < b) cuts.push_back({m.x[a], m.x[b]});
      }
    for (std::size_t n = 0; n < m.size(); ++n)
      if (m.ring[n] >= 0 && t.valence(static_cast<int>(n)) == 1) out.ring_corners.push_back(m.x[n]);
    try {
      out.layout = build_patch_layout(d, std::move(cuts), out.ring_corners);
      // Every patch corner where the map sees it (at the vertex itself)
      // between 1 and 170 degrees (patch_corner_in_range). (The mesher's own
      // layout, level 0, only needs convex corners.)
      for (const Patch& p : out.layout.patches)
        for (int k = 0; k < 4; ++k) {
          const auto& v = p.polygon.vertices;
          const std::size_t c = p.corners[k], n = v.size();
          const Eigen::Vector2d a = v[(c + 1) % n] - v[c], b = v[(c + n - 1) % n] - v[c];
          const bool fine = level == 0 ? cross(a, b) / (a.norm() * b.norm()) > 1e-3 : patch_corner_in_range(a, b);
          if (!fine)
            throw InputError("a patch corner outside 1-170 degrees near (" + std::to_string(v[c].x()) + ", " +
                             std::to_string(v[c].y()) + ")");
        }
    } catch (const InputError& e) {
      if (debugging()) std::fprintf(stderr, "layout rejected at level %d: %s\n", level, e.what());
      if (level == 2) {
        // The optimization left a corner flat or reflex, or the cuts crossing
        // (a tangled start near rings much closer than the patch size): the
        // same mesh without edge rotations.
        note("mesh " + std::to_string(meshes) + ": " + e.what() + "; the same mesh without edge rotations");
        out.stats.optimization_level = level = 1;
        continue;
      }
      // Ring nodes more near the place, and a new mesh optimized in full;
      // once the repairs are used up, the mesher's own nodes (level 0) are the
      // last try (its cuts may cross where the true rings are far from their chords).
      const std::string what = e.what();
      const std::size_t at = what.find("near (");
      Eigen::Vector2d place(0.0, 0.0);
      bool again = false;  // this place failed a repair before: a node more there did not mend it
      if (at != std::string::npos) {
        char* end = nullptr;
        place.x() = std::strtod(what.c_str() + at + 6, &end);
        place.y() = end && *end == ',' ? std::strtod(end + 1, nullptr) : 0.0;
        // (The message gives 6 decimals.)
        const double same = std::max(1e-6 * diam, 2e-6);
        for (const Eigen::Vector2d& p : repaired_at) again = again || (p - place).norm() <= same;
      }
      if (at != std::string::npos && repairs < o.max_repair_rounds && !again) {
        repaired_at.push_back(place);
        mark_nearest_piece(place);
        note("mesh " + std::to_string(meshes) + ": " + what + "; a ring node more there, meshing again");
        split_marked();
        out.stats.repair_rounds = ++repairs;
        out.stats.optimization_level = level = 2;
        continue;
      }
      if (level == 1) {
        // (Also where the same place failed after a node more there: each
        // further round would cost a mesh and its optimization, to the same end.)
        if (again)
          note("mesh " + std::to_string(meshes) + ": " + what +
               " again after a ring node more there; the mesher's own nodes instead");
        out.stats.optimization_level = level = 0;
        continue;
      }
      throw NumericalError("no valid quad layout: " + what);
    }
    QuadLayoutStats& st = out.stats;
    st.patches = out.layout.patches.size();
    st.min_size = so.min_size;
    st.max_size = so.max_size > 0.0 ? so.max_size : 0.125 * diam;
    for (std::size_t n = 0; n < m.size(); ++n) {
      const std::size_t k = t.valence(static_cast<int>(n));
      if (k == 0) continue;
      if (m.ring[n] >= 0) ++st.ring_nodes;
      else ++st.inner_nodes, ++st.valence[std::min<std::size_t>(k, 7)];
    }
    double sum = 0.0;
    st.min_corner_scaled_jacobian = 1.0;
    for (const auto& q : m.quads) {
      const double sj = quad_corner_scaled_jacobian({m.x[q[0]], m.x[q[1]], m.x[q[2]], m.x[q[3]]});
      st.min_corner_scaled_jacobian = std::min(st.min_corner_scaled_jacobian, sj);
      sum += sj;
    }
    st.mean_corner_scaled_jacobian = sum / static_cast<double>(m.quads.size());
    const LayoutCornerQuality w = worst_layout_quality(m, t, quality);
    st.corner_mean_ratio = w.mean_ratio;
    st.corner_scaled_jacobian = w.scaled_jacobian;
    st.seconds = toolkit::seconds_since(t0);
    return out;
  }
}

}  // namespace tspline
