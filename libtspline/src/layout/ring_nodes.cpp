#include "tspline/layout/ring_nodes.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "tspline/boundary/plane.h"

namespace tspline {

RingCurve::RingCurve(const std::vector<Eigen::Vector2d>& vertices) : v_(vertices) {
  arc_.assign(v_.size() + 1, 0.0);
  for (std::size_t i = 0; i < v_.size(); ++i) arc_[i + 1] = arc_[i] + (v_[(i + 1) % v_.size()] - v_[i]).norm();
}

std::pair<std::size_t, double> RingCurve::edge_at(double s) const {
  const double L = length();
  s = arc_mod(s, L);
  if (s < 0.0) s += L;
  // The edge [i, i+1] with arc(i) <= s < arc(i+1): that is the edge of this
  // thread's last call, or one next to it, on most calls (a layout node's
  // corners look up points near each other); else a binary search.
  thread_local const RingCurve* last_ring = nullptr;
  thread_local std::size_t last = 0;
  if (last_ring == this) {
    const std::size_t n = v_.size();
    for (const std::size_t i : {last, last + 1, last + n - 1}) {
      const std::size_t e = i % n;
      if (arc_[e] <= s && s < arc_[e + 1]) {
        last = e;
        return {e, s};
      }
    }
  }
  const auto it = std::upper_bound(arc_.begin(), arc_.end(), s);
  const std::size_t i =
      std::min(static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - arc_.begin()) - 1)), v_.size() - 1);
  last_ring = this, last = i;
  return {i, s};
}

Eigen::Vector2d RingCurve::point(double s_in) const {
  const auto [i, s] = edge_at(s_in);
  const double len = arc_[i + 1] - arc_[i];
  const double t = len > 0.0 ? (s - arc_[i]) / len : 0.0;
  return v_[i] + t * (v_[(i + 1) % v_.size()] - v_[i]);
}

double RingCurve::snap_to_vertex(double s_in, double eps) const {
  const auto [i, s] = edge_at(s_in);
  if (s - arc_[i] <= eps) return arc_[i];
  if (arc_[i + 1] - s <= eps) return i + 1 == v_.size() ? 0.0 : arc_[i + 1];
  return s;
}

Eigen::Vector2d RingCurve::direction(double s_in, double dir) const {
  const auto [i, s] = edge_at(s_in);
  const std::size_t n = v_.size();
  std::size_t e = i;  // the edge [e, e + 1] that leaves the point
  if (dir < 0.0 && s <= arc_[i]) e = (i + n - 1) % n;  // at vertex i, going back: the edge before it
  const Eigen::Vector2d d = v_[(e + 1) % n] - v_[e];
  const double len = d.norm();
  const Eigen::Vector2d u = len > 0.0 ? Eigen::Vector2d(d / len) : Eigen::Vector2d(1.0, 0.0);
  return dir < 0.0 ? Eigen::Vector2d(-u) : u;
}

double RingCurve::turn(std::size_t i) const {
  const std::size_t n = v_.size();
  const Eigen::Vector2d a = v_[i % n] - v_[(i + n - 1) % n], b = v_[(i + 1) % n] - v_[i % n];
  return signed_angle(a, b);
}

std::size_t RingCurve::first_vertex_after(double s) const {
  const double L = length();
  s = arc_mod(s, L);
  if (s < 0.0) s += L;
  return static_cast<std::size_t>(std::upper_bound(arc_.begin(), arc_.end() - 1, s) - arc_.begin());
}

namespace {

// Distance of p from the segment [a, b].
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

}  // namespace

std::pair<double, double> RingCurve::farthest_from_chord(double a, double b) const {
  const double L = length();
  const Eigen::Vector2d pa = point(a), pb = point(b);
  double best = -1.0, at = -1.0;
  // Vertices with arc length in (a, b), b possibly beyond L (wrapping).
  const std::size_t n = v_.size();
  std::size_t i = static_cast<std::size_t>(std::upper_bound(arc_.begin(), arc_.end() - 1, std::fmod(a, L)) - arc_.begin());
  double offset = a >= L ? L : 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (i >= n) i -= n, offset += L;
    const double s = arc_[i] + offset;
    if (s >= b) break;
    if (s > a) {
      const double d = segment_distance(v_[i], pa, pb);
      if (d > best) best = d, at = s;
    }
    ++i;
  }
  return {best, at};
}

std::vector<double> split_long_pieces(const RingCurve& ring, std::vector<double> nodes,
                                      const std::function<double(const Eigen::Vector2d&)>& size, double min_size) {
  if (!size || nodes.empty()) return nodes;
  const double L = ring.length();
  std::vector<double> out;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const double a = nodes[k], b = k + 1 < nodes.size() ? nodes[k + 1] : nodes.front() + L;
    out.push_back(a);
    const double h = std::max(size(ring.point(0.5 * (a + b))), min_size);
    const double chord = (ring.point(b) - ring.point(a)).norm();
    if (!(h > 0.0) || chord <= 1.2 * h) continue;
    const int pieces = static_cast<int>(std::ceil(chord / h - 0.2));
    for (int j = 1; j < pieces; ++j) out.push_back(std::fmod(a + (b - a) * j / pieces, L));
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<double> ring_nodes(const RingCurve& ring, const RingNodeOptions& o,
                               const std::function<double(const Eigen::Vector2d&)>& size) {
  const double L = ring.length();
  const std::size_t n = ring.size();
  // Start from the vertex farthest from vertex 0 and the vertex farthest from that one.
  auto farthest_vertex = [&](const Eigen::Vector2d& from) {
    std::size_t best = 0;
    double d = -1.0;
    for (std::size_t i = 0; i < n; ++i)
      if ((ring.vertex(i) - from).squaredNorm() > d) d = (ring.vertex(i) - from).squaredNorm(), best = i;
    return best;
  };
  const std::size_t i0 = farthest_vertex(ring.vertex(0));
  const std::size_t i1 = farthest_vertex(ring.vertex(i0));
  std::vector<double> nodes = {ring.arc(std::min(i0, i1)), ring.arc(std::max(i0, i1))};
  if (nodes[0] == nodes[1]) nodes.pop_back();
  // Relative Douglas-Peucker on each piece (an explicit stack: pieces can nest deeply).
  std::vector<double> out;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const double a = nodes[k], b = k + 1 < nodes.size() ? nodes[k + 1] : nodes.front() + L;
    std::vector<std::pair<double, double>> stack = {{a, b}};
    std::vector<double> inside;
    while (!stack.empty()) {
      const auto [s, t] = stack.back();
      stack.pop_back();
      if (t - s <= o.min_size) continue;
      const auto [dev, at] = ring.farthest_from_chord(s, t);
      if (at < 0.0) continue;
      const double chord = (ring.point(t) - ring.point(s)).norm();
      if (dev <= o.max_deviation * chord) continue;
      inside.push_back(at);
      stack.push_back({s, at});
      stack.push_back({at, t});
    }
    out.push_back(a);
    for (double s : inside) out.push_back(std::fmod(s, L));
  }
  // Corners of the ring: vertices where it turns by more than corner_turn on the
  // scale of a quarter of the local piece size (the domain's corners, the tips
  // of peninsulas, the heads of inlets), the sharpest first, none within half a
  // piece of a sharper one. Patch corners belong there, not inside a side.
  {
    std::vector<std::pair<double, double>> turns;  // (turn, arc)
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d p = ring.vertex(i);
      const double h = size ? std::max(size(p), o.min_size) : 0.1 * L;
      const double l = std::min(0.25 * h, 0.1 * L);
      const Eigen::Vector2d u = ring.point(ring.arc(i) + l) - p, w = p - ring.point(ring.arc(i) - l);
      const double turn = std::abs(signed_angle(w, u));
      // A vertex sharp at its own edges (a spike or a crack narrower than the
      // quarter piece) is a node too, ahead of every other: inside a side it
      // leaves the patch map J_r about sin^2(phi / 2) there (layout_quality.h),
      // 0.003 for a tip of 6 degrees, where a patch corner has sin(phi) = 0.1.
      const double sharp = std::abs(ring.turn(i));
      if (sharp > o.sharp_turn) turns.push_back({std::numbers::pi + sharp, ring.arc(i)});
      else if (turn > o.corner_turn) turns.push_back({turn, ring.arc(i)});
    }
    std::sort(turns.begin(), turns.end(), std::greater<>());
    std::vector<double> kept;
    for (const auto& [turn, s] : turns) {
      const double h = size ? std::max(size(ring.point(s)), o.min_size) : 0.1 * L;
      bool near = false;
      for (double k : kept) {
        const double d = std::abs(k - s);
        near = near || std::min(d, L - d) < 0.5 * h;
      }
      if (!near) kept.push_back(s);
    }
    // A corner replaces the Douglas-Peucker nodes within a quarter piece of it.
    for (double k : kept) {
      const double h = size ? std::max(size(ring.point(k)), o.min_size) : 0.1 * L;
      std::erase_if(out, [&](double s) {
        const double d = std::abs(k - s);
        return std::min(d, L - d) < 0.25 * h;
      });
    }
    out.insert(out.end(), kept.begin(), kept.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (out.empty()) out.push_back(0.0);
  out = split_long_pieces(ring, std::move(out), size, o.min_size);
  // At least min_nodes_per_ring: split the longest pieces at half their arc length.
  while (out.size() < static_cast<std::size_t>(std::max(o.min_nodes_per_ring, 1))) {
    std::size_t longest = 0;
    double len = -1.0;
    for (std::size_t k = 0; k < out.size(); ++k) {
      const double b = k + 1 < out.size() ? out[k + 1] : out.front() + L;
      if (b - out[k] > len) len = b - out[k], longest = k;
    }
    out.push_back(std::fmod(out[longest] + 0.5 * len, L));
    std::sort(out.begin(), out.end());
  }
  // No two nodes closer (by arc length) than a thousandth of the ring or of the
  // smallest piece size, also across the start of the ring.
  const double gap = std::max(1e-3 * std::min(L, o.min_size > 0.0 ? o.min_size : L), 1e-12 * L);
  std::vector<double> kept;
  for (double s : out)
    if (kept.empty() || s - kept.back() > gap) kept.push_back(s);
  while (kept.size() > 1 && kept.front() + L - kept.back() <= gap) kept.pop_back();
  return kept;
}

}  // namespace tspline
