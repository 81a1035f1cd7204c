#include "tspline/layout/quad_layout.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <unordered_map>

#include "toolkit/timing.h"
#include "tspline/boundary/plane.h"
#include "tspline/errors.h"
#include "tspline/layout/layout_kstar.h"
#include "tspline/layout/layout_optimizer.h"
#include "tspline/layout/layout_quality.h"
#include "tspline/layout/layout_topology.h"
#include "tspline/layout/quad_layout_memo.h"
#include "tspline/layout/quad_mesher.h"
#include "tspline/layout/ring_geometry.h"

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
//  3. a flat single-quad ring corner gets a sheet of quads through it, or
//     where that adds more quads (or corner_sheets is off), its ring is pillowed;
//  4. the node optimization in full, then rotations and the optimization
//     again while rotations are kept.
// `start` becomes the mesh the checks fall back to (the mesher's nodes, after
// any pillowing).
// `first_done`: the first pass (step 1 and, at level 2, the first rotations)
// as an earlier layout of the same domain made it from the same mesh
// (quad_layout_memo.h), instead of making it again; `first_made`: where the
// first pass made here is left.
void optimize_layout(LayoutMesh& m, LayoutMesh& start, const LayoutRings& R, const LayoutQuality& Q,
                     const LayoutAdmissible& admissible, int level, bool corner_sheets, bool guard_corners,
                     QuadLayoutStats& st, const std::atomic<bool>* cancel, const LayoutFirstPass* first_done,
                     LayoutFirstPass* first_made) {
  st.rotations = 0;
  st.openings = 0;
  st.optimization_sweeps = 0;
  st.pillowed_rings = 0;
  st.corner_sheets = 0;
  // Every sweep and rotation batch checks the cancel flag.
  LayoutOptimizationOptions full;
  full.cancel = cancel;
  full.keep_patch_corners_in_range = guard_corners;
  LayoutRotationOptions rotation;
  rotation.cancel = cancel;
  auto rotate = [&]() {
    LayoutRotationReport rr = rotate_layout_edges(m, Q, admissible, rotation);
    st.rotations += rr.kept;
    if (debugging()) std::fprintf(stderr, "layout rotations: %zu tried, %zu kept, %.2f s\n", rr.tried, rr.kept, lap());
    return rr;
  };
  if (debugging()) lap();
  if (level >= 1 && first_done) {
    m = first_done->mesh;
    st.rotations = first_done->rotations;
    st.optimization_sweeps = first_done->optimization_sweeps;
    if (debugging()) std::fprintf(stderr, "layout first pass: an earlier layout's of the same mesh\n");
  } else if (level >= 1) {
    smooth_layout_kstar(m, R);
    if (debugging()) std::fprintf(stderr, "layout K*: %.2f s\n", lap());
    LayoutOptimizationOptions quick = full;
    quick.max_sweeps = 8;
    report_optimization(optimize_layout_nodes(m, Q, admissible, {}, quick), st);
    if (level >= 2) rotate();
    if (first_made) *first_made = {m, st.rotations, st.optimization_sweeps};
  }
  const std::vector<int> flat_corners = flat_ring_corners(m, Q);
  if (!flat_corners.empty()) {
    if (level == 0) m = start;
    // A sheet through each flat corner where the sheets add fewer quads than
    // the pillow layers of their rings would (one per quad edge along them).
    std::vector<char> flat(R.curves.size(), 0);
    for (const int v : flat_corners) flat[m.ring[v]] = 1;
    std::size_t layer_quads = 0;
    const LayoutTopology t(m);
    for (std::size_t q = 0; q < m.quads.size(); ++q)
      for (int j = 0; j < 4; ++j) layer_quads += t.on_ring(static_cast<int>(q), j) && flat[m.ring[m.quads[q][j]]];
    const std::size_t sheet_quads = corner_sheets ? insert_corner_sheets(m, R, flat_corners, layer_quads) : 0;
    if (debugging()) {
      std::fprintf(stderr, "layout flat corners: %zu, sheets add %zu quads (pillow layers %zu)\n", flat_corners.size(),
                   sheet_quads, layer_quads);
      for (const int v : flat_corners) std::fprintf(stderr, "  flat corner (%.4f, %.4f)\n", m.x[v].x(), m.x[v].y());
    }
    if (sheet_quads > 0) {
      st.corner_sheets = flat_corners.size();
    } else {
      st.pillowed_rings = static_cast<std::size_t>(std::count(flat.begin(), flat.end(), 1));
      pillow_rings(m, flat);
    }
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
  for (std::size_t v = 0; v < stats.inner_valence.size(); ++v)
    if (stats.inner_valence[v]) s << ' ' << v << (v == 7 ? "+" : "") << ": " << stats.inner_valence[v];
  s << ")";
  if (stats.pillowed_rings) s << ", " << stats.pillowed_rings << " ring(s) pillowed";
  if (stats.corner_sheets) s << ", " << stats.corner_sheets << " sheet(s) of quads through flat ring corners";
  s.precision(3);
  s << ", worst corner J_r " << stats.corner_mean_ratio << " scaled Jacobian " << stats.corner_scaled_jacobian
    << (stats.optimization_level == 2   ? ""
        : stats.optimization_level == 1 ? " (no edge rotations: they broke it)"
                                        : " (nodes not optimized: that broke it)");
  return s.str();
}

namespace {

// The rounds of build_quad_layout and what they carry from one to the next:
// the ring nodes, the optimization level, the repairs made. A round either
// ends with the layout or changes what the next one starts from: ring nodes
// more where something failed (a repair), or a lower optimization level.
class QuadLayoutBuilder {
 public:
  QuadLayoutBuilder(const Domain& d, const QuadLayoutOptions& o);
  QuadLayoutBuilder(const QuadLayoutBuilder&) = delete;
  QuadLayoutBuilder& operator=(const QuadLayoutBuilder&) = delete;
  QuadLayout build();

 private:
  const std::vector<RingCurve>& rings() const { return R_.curves; }
  void note(const std::string& text) const {
    if (o_.progress) o_.progress(text);
  }
  std::string mesh_name() const { return "mesh " + std::to_string(meshes_); }
  void count_repair() { out_.stats.repair_rounds = ++repairs_; }

  std::size_t marked() const;
  bool split_marked();
  void mark_piece_of_edge(const RingGeometry::Edge& e);
  void mark_nearest_piece(const Eigen::Vector2d& p) { mark_piece_of_edge(geometry_.edge(geometry_.nearest(p))); }

  std::vector<std::vector<Eigen::Vector2d>> straight_rings() const;
  void mark_crossing_chords(const std::vector<std::vector<Eigen::Vector2d>>& straight);
  void mark_blunted_tips(const std::vector<std::vector<Eigen::Vector2d>>& straight);
  std::optional<PlanarQuadMesh> mesh(const std::vector<std::vector<Eigen::Vector2d>>& straight);
  bool marked_untiled(const PlanarQuadMesh& qm);
  LayoutMesh on_true_rings(const PlanarQuadMesh& qm) const;
  std::set<int> violations(const LayoutMesh& lm, bool mark);
  bool undo_violations(LayoutMesh& m, const LayoutMesh& start, int round);
  void make_patch_layout(const LayoutMesh& m, const LayoutTopology& t);
  void recover_from_rejected_layout(const std::string& what);
  void fill_stats(const LayoutMesh& m, const LayoutTopology& t);

  QuadLayoutMemo::Rings memo_domain() const;

  const Domain& d_;
  const QuadLayoutOptions& o_;
  const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  const Eigen::Vector2d lo_, hi_;  // the bounding box of the outer ring
  const double diam_;
  const SizeFieldOptions size_options_;
  const SizeField h_;
  const LayoutRings R_;
  const RingNodeOptions node_options_;
  std::vector<std::vector<double>> nodes_;  // per ring: the arc lengths of its nodes, ascending
  const RingGeometry geometry_;
  const double tol_;
  const LayoutQuality quality_;
  // A node may stay where the optimizer moved it: inside the domain, its cuts off the rings.
  const LayoutAdmissible admissible_;

  QuadLayout out_;
  int meshes_ = 0;  // made by the mesher (rounds that only add ring nodes make none)
  int level_ = 2;
  // Node moves may not put patch corners out of range (LayoutOptimizationOptions::
  // keep_patch_corners_in_range): from the first layout rejected for such a
  // corner on, or from the start (QuadLayoutOptions::guard_patch_corners; the
  // guard also pins nodes where the energy would have them pass).
  bool guard_corners_;
  std::vector<Eigen::Vector2d> level2_failed_at_;  // where a layout optimized in full was rejected
  int repairs_ = 0;  // rounds that added nodes (dropping an optimization level is not one)
  std::vector<Eigen::Vector2d> repaired_at_;  // where a rejected layout got a ring node more
  std::vector<std::set<std::size_t>> to_split_;  // per ring: the pieces that get a node more this round
};

Eigen::Vector2d lower_corner(const Polygon& p) {
  Eigen::Vector2d lo = p.vertices.front();
  for (const auto& v : p.vertices) lo = lo.cwiseMin(v);
  return lo;
}

Eigen::Vector2d upper_corner(const Polygon& p) {
  Eigen::Vector2d hi = p.vertices.front();
  for (const auto& v : p.vertices) hi = hi.cwiseMax(v);
  return hi;
}

SizeFieldOptions absolute_sizes(SizeFieldOptions so, double min_size_fraction, double diam) {
  if (!(so.min_size > 0.0)) so.min_size = min_size_fraction * diam;
  return so;
}

LayoutRings rings_of(const Domain& d) {
  LayoutRings R;
  R.curves.emplace_back(d.outer.vertices);
  for (const Polygon& p : d.holes) R.curves.emplace_back(p.vertices);
  return R;
}

RingNodeOptions with_min_size(RingNodeOptions no, double min_size) {
  if (!(no.min_size > 0.0)) no.min_size = min_size;
  return no;
}

QuadLayoutBuilder::QuadLayoutBuilder(const Domain& d, const QuadLayoutOptions& o)
    : d_(d),
      o_(o),
      lo_(lower_corner(d.outer)),
      hi_(upper_corner(d.outer)),
      diam_((hi_ - lo_).norm()),
      size_options_(absolute_sizes(o.size, o.min_size_fraction, diam_)),
      h_(d, size_options_),
      R_(rings_of(d)),
      node_options_(with_min_size(o.nodes, size_options_.min_size)),
      geometry_(RingGeometry::of_rings(R_.curves)),
      tol_(1e-9 * diam_),
      quality_(R_, o.max_patch_corner_degrees),
      admissible_(admissible_in(geometry_, tol_)),
      guard_corners_(o.guard_patch_corners) {
  // Ring pieces are two quad edges long.
  const auto piece_size = [this](const Eigen::Vector2d& x) { return 2.0 * h_(x); };
  if (!o.start_ring_nodes.empty()) {
    if (o.start_ring_nodes.size() != rings().size())
      throw InputError("quad layout: start_ring_nodes has " + std::to_string(o.start_ring_nodes.size()) +
                       " list(s) for " + std::to_string(rings().size()) + " ring(s)");
    for (std::size_t r = 0; r < rings().size(); ++r) {
      const std::vector<double>& s = o.start_ring_nodes[r];
      const double L = rings()[r].length();
      const bool ascending = std::adjacent_find(s.begin(), s.end(), std::greater_equal<>()) == s.end();
      if (s.empty() || !ascending || !(s.front() >= 0.0) || !(s.back() < L))
        throw InputError("quad layout: start_ring_nodes of ring " + std::to_string(r) +
                         " are not ascending arc lengths in [0, the ring's length)");
    }
    nodes_ = o.start_ring_nodes;
    return;
  }
  for (const RingCurve& r : rings()) nodes_.push_back(ring_nodes(r, node_options_, piece_size));
}

QuadLayout QuadLayoutBuilder::build() {
  for (int round = 0;; ++round) {
    throw_if_cancelled(o_.cancel);
    if (repairs_ > o_.max_repair_rounds)
      throw NumericalError("no quad layout found: the layout still crosses the boundary after " +
                           std::to_string(o_.max_repair_rounds) + " rounds of adding nodes");
    to_split_.assign(rings().size(), {});
    const std::vector<std::vector<Eigen::Vector2d>> straight = straight_rings();
    mark_crossing_chords(straight);
    mark_blunted_tips(straight);
    if (split_marked()) {
      count_repair();
      continue;
    }
    const std::optional<PlanarQuadMesh> qm = mesh(straight);
    if (!qm) {  // the mesher lost a piece of a ring: nodes more there
      split_marked();
      count_repair();
      continue;
    }
    if (marked_untiled(*qm)) {
      if (!split_marked()) throw NumericalError("the quad mesher's quadrilaterals do not tile the domain");
      count_repair();
      continue;
    }
    LayoutMesh start = on_true_rings(*qm);  // the mesher's nodes, on the true rings
    LayoutMesh m = start;
    ++meshes_;
    note(mesh_name() + ": " + std::to_string(m.quads.size()) + " quads from the mesher; optimizing them" +
         (level_ == 2 ? "" : " without edge rotations"));
    const auto t_opt = std::chrono::steady_clock::now();
    std::optional<LayoutFirstPass> first_done;
    LayoutFirstPass first_made;
    if (o_.memo && level_ >= 1)
      first_done = o_.memo->first_pass(memo_domain(), size_options_, nodes_, level_, guard_corners_,
                                       o_.max_patch_corner_degrees);
    optimize_layout(m, start, R_, quality_, admissible_, level_, o_.corner_sheets, guard_corners_, out_.stats,
                    o_.cancel, first_done ? &*first_done : nullptr, &first_made);
    if (o_.memo && level_ >= 1 && !first_done)
      o_.memo->store_first_pass(memo_domain(), size_options_, nodes_, level_, guard_corners_,
                                o_.max_patch_corner_degrees, first_made);
    if (debugging())
      std::fprintf(stderr, "layout round %d: mesh %zu quads at %.2f s, optimized in %.2f s\n", round, m.quads.size(),
                   std::chrono::duration<double>(t_opt - t0_).count(), toolkit::seconds_since(t_opt));
    if (undo_violations(m, start, round)) {
      count_repair();
      out_.stats.optimization_level = level_ = 2;  // the new mesh is optimized in full
      continue;
    }
    const LayoutTopology t(m);
    try {
      make_patch_layout(m, t);
    } catch (const InputError& e) {
      recover_from_rejected_layout(e.what());
      continue;
    }
    fill_stats(m, t);
    out_.ring_nodes = nodes_;
    return std::move(out_);
  }
}

QuadLayoutMemo::Rings QuadLayoutBuilder::memo_domain() const {
  QuadLayoutMemo::Rings rings{d_.outer.vertices};
  for (const Polygon& h : d_.holes) rings.push_back(h.vertices);
  return rings;
}

std::size_t QuadLayoutBuilder::marked() const {
  std::size_t k = 0;
  for (const auto& pieces : to_split_) k += pieces.size();
  return k;
}

bool QuadLayoutBuilder::split_marked() {
  bool any = false;
  for (std::size_t r = 0; r < rings().size(); ++r)
    // From the last piece down: indices of earlier pieces stay valid.
    for (auto it = to_split_[r].rbegin(); it != to_split_[r].rend(); ++it) {
      split_piece(rings()[r], nodes_[r], *it);
      any = true;
    }
  return any;
}

// The piece of its ring that boundary edge e lies on.
void QuadLayoutBuilder::mark_piece_of_edge(const RingGeometry::Edge& e) {
  to_split_[e.ring].insert(piece_of(nodes_[e.ring], rings()[e.ring].arc(e.index)));
}

// Each ring as the polygon of its nodes (chords between them).
std::vector<std::vector<Eigen::Vector2d>> QuadLayoutBuilder::straight_rings() const {
  std::vector<std::vector<Eigen::Vector2d>> straight(rings().size());
  for (std::size_t r = 0; r < rings().size(); ++r)
    for (double s : nodes_[r]) straight[r].push_back(rings()[r].point(s));
  return straight;
}

// The straight rings must be simple and disjoint, and no chord may cut off a
// piece of another ring: the pieces involved where one does are marked.
void QuadLayoutBuilder::mark_crossing_chords(const std::vector<std::vector<Eigen::Vector2d>>& straight) {
  std::vector<RingGeometry::Edge> chords;
  for (std::size_t r = 0; r < straight.size(); ++r)
    for (std::size_t k = 0; k < straight[r].size(); ++k)
      chords.push_back({straight[r][k], straight[r][(k + 1) % straight[r].size()], static_cast<int>(r), k});
  const RingGeometry cg(chords, lo_, hi_);
  for (std::size_t c = 0; c < chords.size(); ++c) {
    const auto& e = chords[c];
    for (int o2 : cg.near(e.a.cwiseMin(e.b), e.a.cwiseMax(e.b))) {
      if (o2 <= static_cast<int>(c)) continue;
      const auto& f = cg.edge(o2);
      const std::size_t n = straight[e.ring].size();
      const bool adjacent = f.ring == e.ring && (f.index == (e.index + 1) % n || e.index == (f.index + 1) % n);
      if (adjacent && n > 2) continue;
      if (segments_intersect(e.a, e.b, f.a, f.b)) to_split_[e.ring].insert(e.index), to_split_[f.ring].insert(f.index);
    }
  }
  for (const auto& e : chords)
    for (int g : geometry_.near(e.a.cwiseMin(e.b), e.a.cwiseMax(e.b))) {
      const auto& f = geometry_.edge(g);
      if (f.ring != e.ring && segments_intersect(e.a, e.b, f.a, f.b)) {
        to_split_[e.ring].insert(e.index);
        mark_piece_of_edge(f);
      }
    }
}

// At a sharp tip of the coast (the domain's angle there below 60 or above
// 300 degrees on the scale of a fifth of the pieces next to the node) the
// straight ring must be as sharp: the chord to a neighbour and the ring's
// own direction within 35 degrees; else the mesher sees a blunt corner where
// the coast has a tip, and gives it too few quads (a reflex tip of 340
// degrees split in two corners of 170 degrees).
void QuadLayoutBuilder::mark_blunted_tips(const std::vector<std::vector<Eigen::Vector2d>>& straight) {
  for (std::size_t r = 0; r < rings().size(); ++r) {
    const std::size_t n = nodes_[r].size();
    if (n < 3) continue;
    const RingCurve& ring = rings()[r];
    const double L = ring.length();
    for (std::size_t k = 0; k < n; ++k) {
      const double s = nodes_[r][k];
      const Eigen::Vector2d p = ring.point(s);
      double len[2];
      Eigen::Vector2d near[2], chord[2];
      for (const int side : {0, 1}) {
        const std::size_t other = side == 0 ? (k + 1) % n : (k + n - 1) % n;
        len[side] = side == 0 ? nodes_[r][other] - s : s - nodes_[r][other];
        if (len[side] <= 0.0) len[side] += L;
        chord[side] = straight[r][other] - p;
        near[side] = ring.point(s + (side == 0 ? 1.0 : -1.0) * 0.2 * len[side]) - p;
      }
      // The domain's angle at the node from the forward to the backward direction
      // (the domain on the left of the outer ring, on the right of holes).
      double phi = signed_angle(near[0], near[1]);
      if (R_.direction(static_cast<int>(r)) < 0.0) phi = -phi;
      if (phi < 0.0) phi += 2.0 * std::numbers::pi;
      if (phi > std::numbers::pi / 3.0 && phi < 5.0 * std::numbers::pi / 3.0) continue;
      for (const int side : {0, 1}) {
        const double angle = std::abs(signed_angle(chord[side], near[side]));
        if (angle > 35.0 * std::numbers::pi / 180.0 && len[side] > 2.0 * node_options_.min_size)
          to_split_[r].insert(side == 0 ? k : (k + n - 1) % n);
      }
    }
  }
}

// The quad mesh of the straight rings, or none where Gmsh could not recover a
// boundary segment ("... on curve N ..."): that piece and its neighbours are
// marked for a node more.
std::optional<PlanarQuadMesh> QuadLayoutBuilder::mesh(const std::vector<std::vector<Eigen::Vector2d>>& straight) {
  try {
    if (o_.memo)
      if (std::optional<PlanarQuadMesh> known = o_.memo->mesh(memo_domain(), size_options_, nodes_))
        return known;
    PlanarQuadMesh made = quad_mesh(straight, h_);
    if (o_.memo) o_.memo->store_mesh(memo_domain(), size_options_, nodes_, made);
    return made;
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    const std::size_t at = what.find("on curve ");
    if (at == std::string::npos) throw;
    long long curve = std::atoll(what.c_str() + at + 9) - 1;  // line tags count the segments from 1
    std::size_t r = 0;
    while (r < straight.size() && curve >= static_cast<long long>(straight[r].size()))
      curve -= static_cast<long long>(straight[r].size()), ++r;
    if (r == straight.size() || curve < 0) throw;
    const std::size_t n = straight[r].size(), k = static_cast<std::size_t>(curve);
    for (const std::size_t j : {(k + n - 1) % n, k, (k + 1) % n}) to_split_[r].insert(j);
    note("mesh " + std::to_string(meshes_ + 1) + ": the quad mesher lost a piece of ring " + std::to_string(r) +
         "; 3 ring nodes more there, meshing again");
    return std::nullopt;
  }
}

// The mesh must tile the straight domain: every edge used by two quads in
// opposite directions, or by one quad along a ring (between nodes of that
// ring). Gmsh can mesh a sliver inside a hole, or lose a ring node's curve
// where straight pieces nearly touch: the pieces nearest such edges are
// marked. Returns whether the mesh fails to tile.
bool QuadLayoutBuilder::marked_untiled(const PlanarQuadMesh& qm) {
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
  return broken;
}

// The mesh with its boundary nodes on the true rings: each at the same
// fraction of its piece's arc length as of the chord.
LayoutMesh QuadLayoutBuilder::on_true_rings(const PlanarQuadMesh& qm) const {
  LayoutMesh m{qm.nodes, qm.ring, std::vector<double>(qm.nodes.size(), 0.0), qm.quads};
  for (std::size_t n = 0; n < m.size(); ++n) {
    if (m.ring[n] < 0) continue;
    const auto& nr = nodes_[m.ring[n]];
    const RingCurve& ring = rings()[m.ring[n]];
    const double L = ring.length();
    const std::size_t k = static_cast<std::size_t>(qm.segment[n]);
    const double a = nr[k], b = k + 1 < nr.size() ? nr[k + 1] : nr.front() + L;
    m.arc[n] = ring.snap_to_vertex(a + qm.t[n] * (b - a), 0.01 * (b - a));
    m.x[n] = ring.point(m.arc[n]);
  }
  return m;
}

// The nodes of lm in a violation of the true geometry: an inner node outside
// the domain, or a cut across a ring. With `mark`, the ring pieces nearest
// each violation are marked.
std::set<int> QuadLayoutBuilder::violations(const LayoutMesh& lm, bool mark) {
  std::set<int> involved;
  const LayoutTopology t(lm);
  for (std::size_t n = 0; n < lm.size(); ++n)
    if (lm.ring[n] < 0 && t.valence(static_cast<int>(n)) > 0 && !geometry_.inside(lm.x[n])) {
      involved.insert(static_cast<int>(n));
      if (mark) mark_nearest_piece(lm.x[n]);
    }
  for (std::size_t q = 0; q < lm.quads.size(); ++q)
    for (int j = 0; j < 4; ++j) {
      const int a = lm.quads[q][j], b = lm.quads[q][(j + 1) % 4];
      if (t.on_ring(static_cast<int>(q), j) || a > b) continue;  // each cut once
      const bool a_on = lm.ring[a] >= 0, b_on = lm.ring[b] >= 0;
      const int g = geometry_.crossing(lm.x[a], lm.x[b], a_on, b_on, tol_);
      // No crossing: a violation only between two ring nodes with the cut outside (admits_cut).
      if (g < 0 && geometry_.admits_cut(lm.x[a], lm.x[b], a_on, b_on, tol_)) continue;
      involved.insert(a), involved.insert(b);
      if (!mark) continue;
      if (g < 0)
        mark_nearest_piece(0.5 * (lm.x[a] + lm.x[b]));
      else
        mark_piece_of_edge(geometry_.edge(g));
    }
  return involved;
}

// Checks on the true geometry: inner nodes inside, cuts off the rings. The
// nodes involved in a violation go back where the mesher put them (with the
// quads of the mesher, if rotations changed them); what still fails gets ring
// nodes more near it. Returns whether any were marked (and so split).
bool QuadLayoutBuilder::undo_violations(LayoutMesh& m, const LayoutMesh& start, int round) {
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
  const std::size_t bad = violations(m, true).size();
  if (bad > 0)
    note(mesh_name() + ": " + std::to_string(bad) + " node(s) outside the domain or with cuts across its boundary; " +
         std::to_string(marked()) + " ring node(s) more there, meshing again");
  return split_marked();
}

// The layout: inner edges are cuts, ring nodes of one quad are ring corners.
// \throw InputError naming the place where a patch corner is out of range
// (patch_corner_in_range) or the cuts do not make a layout.
void QuadLayoutBuilder::make_patch_layout(const LayoutMesh& m, const LayoutTopology& t) {
  std::vector<Cut> cuts;
  out_.ring_corners.clear();
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    for (int j = 0; j < 4; ++j) {
      const int a = m.quads[q][j], b = m.quads[q][(j + 1) % 4];
      if (!t.on_ring(static_cast<int>(q), j) && a < b) cuts.push_back({m.x[a], m.x[b]});
    }
  for (std::size_t n = 0; n < m.size(); ++n)
    if (m.ring[n] >= 0 && t.valence(static_cast<int>(n)) == 1) out_.ring_corners.push_back(m.x[n]);
  out_.layout = build_patch_layout(d_, std::move(cuts), out_.ring_corners);
  // Every patch corner where the map sees it (at the vertex itself) between 1
  // and 170 degrees (QuadLayoutOptions::max_patch_corner_degrees,
  // patch_corner_in_range). (The mesher's own layout, level 0, only needs
  // convex corners.)
  for (const Patch& p : out_.layout.patches)
    for (int k = 0; k < 4; ++k) {
      const auto& v = p.polygon.vertices;
      const std::size_t c = p.corners[k], n = v.size();
      const Eigen::Vector2d a = v[(c + 1) % n] - v[c], b = v[(c + n - 1) % n] - v[c];
      const bool fine =
          level_ == 0 ? cross(a, b) / (a.norm() * b.norm()) > 1e-3 : quality_.corner_in_range(a, b);
      if (!fine) {
        std::ostringstream range;
        range << "a patch corner outside 1-" << quality_.max_corner_degrees() << " degrees near (";
        throw InputError(range.str() + std::to_string(v[c].x()) + ", " + std::to_string(v[c].y()) + ")");
      }
    }
}

// After make_patch_layout rejected this round's mesh (`what`): the first
// patch corner out of range makes the node moves keep corners in range from
// then on (the same mesh again, guard_corners_); after that level 2 becomes
// level 1 (the same mesh without edge rotations: the optimization left a
// corner flat or reflex, or cuts crossing near rings much closer than the
// patch size), except at a place where level 2 failed before. Else ring
// nodes more near the place named, and a new mesh optimized in full; once the repairs are used up, or a node more at the
// same place did not mend it, the mesher's own nodes (level 0) are the last
// try (its cuts may cross where the true rings are far from their chords).
// \throw NumericalError when level 0 fails too.
void QuadLayoutBuilder::recover_from_rejected_layout(const std::string& what) {
  if (debugging()) std::fprintf(stderr, "layout rejected at level %d: %s\n", level_, what.c_str());
  const std::size_t at = what.find("near (");
  Eigen::Vector2d place(0.0, 0.0);
  bool again = false;         // this place failed a repair before: a node more there did not mend it
  bool level2_again = false;  // a layout optimized in full failed here before
  if (at != std::string::npos) {
    char* end = nullptr;
    place.x() = std::strtod(what.c_str() + at + 6, &end);
    place.y() = end && *end == ',' ? std::strtod(end + 1, nullptr) : 0.0;
    const double same = std::max(1e-6 * diam_, 2e-6);  // (the message gives 6 decimals)
    const auto near_one_of = [&](const std::vector<Eigen::Vector2d>& places) {
      return std::any_of(places.begin(), places.end(),
                         [&](const Eigen::Vector2d& p) { return (p - place).norm() <= same; });
    };
    again = near_one_of(repaired_at_);
    level2_again = near_one_of(level2_failed_at_);
  }
  if (level_ == 2 && !guard_corners_ && what.find("patch corner") != std::string::npos) {
    note(mesh_name() + ": " + what + "; the same mesh, no node move allowed to put a patch corner out of range");
    guard_corners_ = true;
    if (at != std::string::npos) level2_failed_at_.push_back(place);
    return;
  }
  // A place where a layout optimized in full failed before gets a ring node
  // more (below); elsewhere level 2 first becomes level 1, which would fail
  // elsewhere and come back to level 2 and this place with its next repair.
  if (level_ == 2 && !(level2_again && !again && repairs_ < o_.max_repair_rounds)) {
    if (at != std::string::npos) level2_failed_at_.push_back(place);
    note(mesh_name() + ": " + what + "; the same mesh without edge rotations");
    out_.stats.optimization_level = level_ = 1;
    return;
  }
  if (at != std::string::npos && repairs_ < o_.max_repair_rounds && !again) {
    repaired_at_.push_back(place);
    mark_nearest_piece(place);
    note(mesh_name() + ": " + what + "; a ring node more there, meshing again");
    split_marked();
    count_repair();
    out_.stats.optimization_level = level_ = 2;
    return;
  }
  if (level_ == 1) {
    // (Each further round would cost a mesh and its optimization, to the same end.)
    if (again) note(mesh_name() + ": " + what + " again after a ring node more there; the mesher's own nodes instead");
    out_.stats.optimization_level = level_ = 0;
    return;
  }
  throw NumericalError("no valid quad layout: " + what);
}

void QuadLayoutBuilder::fill_stats(const LayoutMesh& m, const LayoutTopology& t) {
  QuadLayoutStats& st = out_.stats;
  st.patches = out_.layout.patches.size();
  st.min_size = size_options_.min_size;
  st.max_size = size_options_.max_size > 0.0 ? size_options_.max_size : 0.125 * diam_;
  for (std::size_t n = 0; n < m.size(); ++n) {
    const std::size_t k = t.valence(static_cast<int>(n));
    if (k == 0) continue;
    if (m.ring[n] >= 0)
      ++st.ring_nodes;
    else
      ++st.inner_nodes, ++st.inner_valence[std::min<std::size_t>(k, 7)];
  }
  double sum = 0.0;
  st.straight_min_scaled_jacobian = 1.0;
  for (const auto& q : m.quads) {
    const double sj = quad_corner_scaled_jacobian({m.x[q[0]], m.x[q[1]], m.x[q[2]], m.x[q[3]]});
    st.straight_min_scaled_jacobian = std::min(st.straight_min_scaled_jacobian, sj);
    sum += sj;
  }
  st.straight_mean_scaled_jacobian = sum / static_cast<double>(m.quads.size());
  const LayoutCornerQuality w = worst_layout_quality(m, t, quality_);
  st.corner_mean_ratio = w.mean_ratio;
  st.corner_scaled_jacobian = w.scaled_jacobian;
  st.seconds = toolkit::seconds_since(t0_);
}

}  // namespace

QuadLayout build_quad_layout(const Domain& d, const QuadLayoutOptions& o) {
  if (!quad_mesher_available()) quad_mesh({}, {});  // throws the InputError that explains it
  QuadLayoutBuilder builder(d, o);
  return builder.build();
}

}  // namespace tspline
