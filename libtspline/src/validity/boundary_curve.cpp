// Simplicity of the map's boundary curve; see boundary_curve.h for the method.
#include "tspline/validity/boundary_curve.h"

#include <CGAL/Bbox_2.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "tspline/spline/bezier_extraction.h"
#include "toolkit/errors.h"

namespace tspline {

namespace {

struct Piece {
  std::array<Eigen::Vector2d, 4> P;  // Bezier control points, in curve order
  Eigen::Vector2d uv0, uv1;          // parametric end points on the border of the square
  int depth = 0;
};

using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 2, std::size_t>;

// Border segments of one element, in the CCW order of the border: bottom
// (xi increasing), right (eta increasing), top (xi decreasing), left (eta decreasing).
void element_border_segments(const BezierElement& e, const std::vector<Eigen::Vector2d>& cp,
                             std::array<std::vector<Piece>, 4>& sides, std::array<std::vector<double>, 4>& keys) {
  std::array<Eigen::Vector2d, 16> X;
  std::array<double, 16> W{};
  for (auto& x : X) x.setZero();
  for (Eigen::Index r = 0; r < e.C.rows(); ++r)
    for (int k = 0; k < 16; ++k) {
      X[k] += e.C(r, k) * cp[e.functions[r]];
      W[k] += e.C(r, k);
    }
  auto make = [&](int side, std::array<int, 4> idx, Eigen::Vector2d uv0, Eigen::Vector2d uv1, double key) {
    Piece p;
    for (int i = 0; i < 4; ++i) {
      if (std::abs(W[idx[i]] - 1.0) > 1e-9)
        throw toolkit::InternalError("check_boundary_curve: the map's weights are not 1 on the border");
      p.P[i] = X[idx[i]] / W[idx[i]];
    }
    p.uv0 = uv0, p.uv1 = uv1;
    sides[side].push_back(p);
    keys[side].push_back(key);
  };
  const Eigen::Vector2d lo = e.lo, hi = e.hi;
  if (lo.y() == 0.0) make(0, {0, 1, 2, 3}, {lo.x(), 0.0}, {hi.x(), 0.0}, lo.x());
  if (hi.x() == 1.0) make(1, {3, 7, 11, 15}, {1.0, lo.y()}, {1.0, hi.y()}, lo.y());
  if (hi.y() == 1.0) make(2, {15, 14, 13, 12}, {hi.x(), 1.0}, {lo.x(), 1.0}, -hi.x());
  if (lo.x() == 0.0) make(3, {12, 8, 4, 0}, {0.0, hi.y()}, {0.0, lo.y()}, -hi.y());
}

std::array<Piece, 2> split(const Piece& p) {
  const auto& P = p.P;
  const Eigen::Vector2d a = 0.5 * (P[0] + P[1]), b = 0.5 * (P[1] + P[2]), c = 0.5 * (P[2] + P[3]);
  const Eigen::Vector2d d = 0.5 * (a + b), f = 0.5 * (b + c), m = 0.5 * (d + f);
  const Eigen::Vector2d um = 0.5 * (p.uv0 + p.uv1);
  Piece l{{P[0], a, d, m}, p.uv0, um, p.depth + 1};
  Piece r{{m, f, c, P[3]}, um, p.uv1, p.depth + 1};
  return {l, r};
}

// All control point differences of the pieces in one open half-plane
// (sufficient test: against their normalized sum).
bool monotone(const Piece* a, const Piece* b, double tiny) {
  Eigen::Vector2d v[6];
  int n = 0;
  for (const Piece* p : {a, b}) {
    if (!p) continue;
    for (int i = 0; i < 3; ++i) v[n++] = p->P[i + 1] - p->P[i];
  }
  Eigen::Vector2d d = Eigen::Vector2d::Zero();
  int nonzero = 0;
  for (int i = 0; i < n; ++i)
    if (v[i].norm() > tiny) d += v[i].normalized(), ++nonzero;
  if (nonzero == 0 || d.norm() < 1e-12) return false;
  for (int i = 0; i < n; ++i)
    if (v[i].norm() > tiny && !(d.dot(v[i]) > 1e-12 * v[i].norm() * d.norm())) return false;
  return true;
}

// The border segments of the map's Bezier elements as one closed curve, side
// by side in the CCW order of the border.
std::vector<Piece> boundary_pieces(const TSplineMap& map, const BezierExtraction& ex) {
  std::array<std::vector<Piece>, 4> sides;
  std::array<std::vector<double>, 4> keys;
  for (const BezierElement& e : ex.elements()) element_border_segments(e, map.control_points(), sides, keys);
  std::vector<Piece> pieces;
  for (int s = 0; s < 4; ++s) {
    std::vector<std::size_t> order(sides[s].size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[s][a] < keys[s][b]; });
    for (std::size_t i : order) pieces.push_back(sides[s][i]);
  }
  return pieces;
}

// The diagonal of the bounding box of the pieces' control points.
double control_box_diagonal(const std::vector<Piece>& pieces) {
  Eigen::Vector2d lo = pieces.front().P[0], hi = lo;
  for (const Piece& p : pieces)
    for (const auto& q : p.P) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  return (hi - lo).norm();
}

// The pieces not proven apart from the rest of the curve in one round.
struct Conflicts {
  std::vector<char> bad;                                    // per piece
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  // overlapping boxes, i < j
  bool any() const { return std::find(bad.begin(), bad.end(), 1) != bad.end(); }
};

// A piece is bad if it is not monotone, or if its box (the control points'
// bounding box, padded by pad) overlaps another piece's, unless the two are
// neighbours along the curve and monotone together.
Conflicts find_conflicts(const std::vector<Piece>& pieces, double pad, double tiny) {
  const std::size_t n = pieces.size();
  Conflicts out{std::vector<char>(n, 0), {}};
  for (std::size_t i = 0; i < n; ++i)
    if (!monotone(&pieces[i], nullptr, tiny)) out.bad[i] = 1;
  std::vector<Box> boxes;
  boxes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector2d a = pieces[i].P[0], b = a;
    for (const auto& q : pieces[i].P) a = a.cwiseMin(q), b = b.cwiseMax(q);
    boxes.emplace_back(CGAL::Bbox_2(a.x() - pad, a.y() - pad, b.x() + pad, b.y() + pad), i);
  }
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& A, const Box& B) {
    std::size_t i = A.info(), j = B.info();
    if (i > j) std::swap(i, j);
    const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
    if (adjacent) {
      const Piece& first = (j == i + 1) ? pieces[i] : pieces[j];
      const Piece& second = (j == i + 1) ? pieces[j] : pieces[i];
      if (monotone(&first, &second, tiny)) return;
    }
    out.bad[i] = out.bad[j] = 1;
    out.pairs.emplace_back(i, j);
  });
  return out;
}

bool can_split(const std::vector<Piece>& pieces, const std::vector<char>& bad, int max_depth) {
  bool can = false;
  for (std::size_t i = 0; i < pieces.size(); ++i) can = can || (bad[i] && pieces[i].depth < max_depth);
  return can;
}

// The pieces with each bad one halved unless it is at the depth limit.
std::vector<Piece> split_bad(const std::vector<Piece>& pieces, const std::vector<char>& bad, int max_depth) {
  std::vector<Piece> next;
  next.reserve(pieces.size() + 64);
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    if (bad[i] && pieces[i].depth < max_depth) {
      const auto two = split(pieces[i]);
      next.push_back(two[0]);
      next.push_back(two[1]);
    } else {
      next.push_back(pieces[i]);
    }
  }
  return next;
}

// The conflicts that no split resolved: the parametric midpoints of the bad
// pieces, and the message naming where the first of them starts.
void report_not_simple(const std::vector<Piece>& pieces, const Conflicts& c, BoundaryCurveCheck& out) {
  for (std::size_t i = 0; i < pieces.size(); ++i)
    if (c.bad[i]) out.conflicts.push_back(0.5 * (pieces[i].uv0 + pieces[i].uv1));
  const std::size_t k = c.pairs.empty()
                            ? static_cast<std::size_t>(std::find(c.bad.begin(), c.bad.end(), 1) - c.bad.begin())
                            : c.pairs.front().first;
  const Eigen::Vector2d at = pieces[k].P[0];
  std::ostringstream s;
  s << "the boundary curve of the map is not proven simple: it crosses itself, or two of its parts come "
       "closer than the check resolves, near ("
    << at.x() << ", " << at.y() << ")";
  out.message = s.str();
}

}  // namespace

BoundaryCurveCheck check_boundary_curve(const TSplineMap& map, int max_depth) {
  if (max_depth < 0 || max_depth > 20) throw toolkit::InputError("check_boundary_curve: max_depth out of range");
  return check_boundary_curve(map, BezierExtraction(map.basis()), max_depth);
}

BoundaryCurveCheck check_boundary_curve(const TSplineMap& map, const BezierExtraction& extraction,
                                        int max_depth) {
  if (max_depth < 0 || max_depth > 20)
    throw toolkit::InputError("check_boundary_curve: max_depth out of range");
  std::vector<Piece> pieces = boundary_pieces(map, extraction);
  BoundaryCurveCheck out;
  out.segments = pieces.size();
  const double diag = control_box_diagonal(pieces);
  const double pad = 1e-12 * diag, tiny = 1e-14 * diag;
  constexpr std::size_t kMaxPieces = 1u << 20;
  // Rounds of subdivision: the bad pieces halved until none is left, none can
  // be halved (max_depth) or there are too many.
  for (;;) {
    const Conflicts c = find_conflicts(pieces, pad, tiny);
    out.pieces = pieces.size();
    if (!c.any()) {
      out.simple = true;
      return out;
    }
    if (!can_split(pieces, c.bad, max_depth) || pieces.size() > kMaxPieces) {
      report_not_simple(pieces, c, out);
      return out;
    }
    pieces = split_bad(pieces, c.bad, max_depth);
  }
}

}  // namespace tspline
