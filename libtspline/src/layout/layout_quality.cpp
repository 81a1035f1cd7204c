#include "tspline/layout/layout_quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "tspline/boundary/plane.h"
#include "tspline/errors.h"

namespace tspline {
namespace {


// Arc length from a to b going in direction dir on a ring of length L, in [0, L).
double arc_between(double a, double b, double dir, double L) {
  double d = dir > 0.0 ? b - a : a - b;
  d = arc_mod(d, L);
  return d < 0.0 ? d + L : d;
}

}  // namespace

LayoutQuality::LayoutQuality(const LayoutRings& rings, double max_corner_degrees)
    : rings_(rings),
      max_corner_degrees_(max_corner_degrees),
      obtuse_sine_(obtuse_corner_sine(max_corner_degrees)) {
  for (std::size_t r = 0; r < rings.curves.size(); ++r) {
    const RingCurve& c = rings.curves[r];
    const std::size_t n = c.size();
    std::vector<std::vector<double>> levels(1, std::vector<double>(2 * n));
    for (std::size_t i = 0; i < 2 * n; ++i) {
      // The domain's inner angle: pi - turn with the domain on the left (outer
      // ring), pi + turn with it on the right (holes).
      const double phi = std::numbers::pi - rings.direction(static_cast<int>(r)) * c.turn(i % n);
      const double k = std::sin(0.5 * phi);
      levels[0][i] = k * k;
    }
    for (std::size_t w = 1; 2 * w <= 2 * n; w *= 2) {
      const std::vector<double>& prev = levels.back();
      std::vector<double> next(2 * n - 2 * w + 1);
      for (std::size_t i = 0; i < next.size(); ++i) next[i] = std::min(prev[i], prev[i + w]);
      levels.push_back(std::move(next));
    }
    table_.push_back(std::move(levels));
  }
}

double LayoutQuality::kink_min(int r, std::size_t i0, std::size_t i1) const {
  if (i1 <= i0) return 1.0;
  const auto& levels = table_[r];
  const std::size_t n = rings_.curves[r].size();
  if (i1 - i0 > n) i1 = i0 + n;  // the whole ring
  std::size_t k = 0;
  while ((std::size_t{2} << k) <= i1 - i0) ++k;
  return std::min(levels[k][i0], levels[k][i1 - (std::size_t{1} << k)]);
}

double LayoutQuality::side_length(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const {
  const int a = m.quads[q][j], b = m.quads[q][(j + 1) % 4];
  if (!t.on_ring(q, j) || m.ring[a] < 0 || m.ring[a] != m.ring[b]) return (m.x[b] - m.x[a]).norm();
  const int r = m.ring[a];
  return arc_between(m.arc[a], m.arc[b], rings_.direction(r), rings_.curves[r].length());
}

std::pair<Eigen::Vector2d, Eigen::Vector2d> LayoutQuality::corner_vectors(const LayoutMesh& m,
                                                                          const LayoutTopology& t, int q, int j,
                                                                          double scale) const {
  std::array<std::pair<Eigen::Vector2d, Eigen::Vector2d>, 1> out;
  corner_vectors_at(m, t, q, j, std::span<const double>(&scale, 1), out.data());
  return out[0];
}

int LayoutQuality::corner_vectors_at(const LayoutMesh& m, const LayoutTopology& t, int q, int j,
                                     std::span<const double> scales,
                                     std::pair<Eigen::Vector2d, Eigen::Vector2d>* out) const {
  const int v = m.quads[q][j], next = m.quads[q][(j + 1) % 4], prev = m.quads[q][(j + 3) % 4];
  const int r = m.ring[v];
  const Eigen::Vector2d e1 = m.x[next] - m.x[v], e2 = m.x[prev] - m.x[v];
  if (r < 0) {  // a cut corner: the same at every scale
    out[0] = {e1, e2};
    return 1;
  }
  // The ring's direction from the node, going dir, on the scale of scale x len.
  const RingCurve& c = rings_.curves[r];
  auto along = [&](double dir, double len, double scale) -> Eigen::Vector2d {
    if (scale <= 0.0) return c.direction(m.arc[v], dir) * len;
    const Eigen::Vector2d chord = c.point(m.arc[v] + dir * scale * len) - m.x[v];
    const double l = chord.norm();
    return l > 0.0 ? Eigen::Vector2d(chord * (len / l)) : Eigen::Vector2d(c.direction(m.arc[v], dir) * len);
  };
  const int jp = (j + 3) % 4;
  const bool ring_next = t.on_ring(q, j) && m.ring[next] == r, ring_prev = t.on_ring(q, jp) && m.ring[prev] == r;
  const double len1 = ring_next ? side_length(m, t, q, j) : 0.0, len2 = ring_prev ? side_length(m, t, q, jp) : 0.0;
  const double dir = rings_.direction(r);
  for (std::size_t k = 0; k < scales.size(); ++k)
    out[k] = {ring_next ? along(dir, len1, scales[k]) : e1, ring_prev ? along(-dir, len2, scales[k]) : e2};
  return static_cast<int>(scales.size());
}

double obtuse_corner_sine(double max_degrees) {
  if (!(max_degrees > 90.0 && max_degrees < 180.0))
    throw InputError("the widest patch corner must be between 90 and 180 degrees (exclusive)");
  return std::ceil(1000.0 * std::sin((180.0 - max_degrees) * std::numbers::pi / 180.0)) / 1000.0;
}

namespace {

bool corner_in_range_sine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double obtuse_sine) {
  const double l = a.norm() * b.norm();
  const double sn = l > 0.0 ? cross(a, b) / l : -1.0;
  return sn > 0.0175 && (a.dot(b) > 0.0 || sn > obtuse_sine);
}

}  // namespace

bool patch_corner_in_range(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double max_degrees) {
  return corner_in_range_sine(a, b, obtuse_corner_sine(max_degrees));
}

bool LayoutQuality::corner_in_range(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
  return corner_in_range_sine(a, b, obtuse_sine_);
}

LayoutCornerQuality LayoutQuality::corner(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const {
  LayoutCornerQuality w{1.0, 1.0};
  std::array<std::pair<Eigen::Vector2d, Eigen::Vector2d>, corner_scales.size()> vectors;
  const int scales = corner_vectors_at(m, t, q, j, corner_scales, vectors.data());
  for (int k = 0; k < scales; ++k) {
    const auto& [e1, e2] = vectors[k];
    const double det = cross(e1, e2), a = e1.squaredNorm(), b = e2.squaredNorm();
    if (!(a > 0.0 && b > 0.0)) return {-1.0, -1.0};
    w.mean_ratio = std::min(w.mean_ratio, 2.0 * det / (a + b));
    w.scaled_jacobian = std::min(w.scaled_jacobian, det / std::sqrt(a * b));
  }
  return w;
}

LayoutQuality::SideVertices LayoutQuality::side_vertices(const LayoutMesh& m, const LayoutTopology& t, int q,
                                                         int j) const {
  const int a = m.quads[q][j], b = m.quads[q][(j + 1) % 4];
  const int r = m.ring[a];
  if (!t.on_ring(q, j) || r < 0 || m.ring[b] != r) return {};
  const RingCurve& c = rings_.curves[r];
  const double len = side_length(m, t, q, j);
  // The side covers arc lengths (start, start + len) going forward.
  double start = rings_.direction(r) > 0.0 ? m.arc[a] : m.arc[b];
  start = arc_mod(start, c.length());
  if (start < 0.0) start += c.length();
  const std::size_t i0 = c.first_vertex_after(start);
  // The first vertex at or past start + len, by binary search on the doubled
  // list (vertex i >= n is vertex i - n one lap on).
  const std::size_t n = c.size();
  const double end = start + len;
  auto arc_u = [&](std::size_t i) { return i < n ? c.arc(i) : c.arc(i - n) + c.length(); };
  std::size_t lo = i0, hi = i0 + n;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (arc_u(mid) < end) lo = mid + 1;
    else hi = mid;
  }
  return {r, i0, lo};
}

double LayoutQuality::side_kinks(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const {
  return side_kinks(side_vertices(m, t, q, j));
}

double LayoutQuality::side_shape(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const {
  return side_shape(m, q, j, side_vertices(m, t, q, j));
}

double LayoutQuality::side_shape(const LayoutMesh& m, int q, int j, const SideVertices& v) const {
  if (v.ring < 0 || v.i1 <= v.i0) return 1.0;
  const RingCurve& c = rings_.curves[v.ring];
  const Eigen::Vector2d a = m.x[m.quads[q][j]], b = m.x[m.quads[q][(j + 1) % 4]];
  const double chord = (b - a).norm();
  if (!(chord > 0.0)) return 0.0;
  const Eigen::Vector2d u = (b - a) / chord;
  // The opposite side's line, from corner j + 2 to j + 3: the patch on its left.
  const Eigen::Vector2d o0 = m.x[m.quads[q][(j + 2) % 4]], o1 = m.x[m.quads[q][(j + 3) % 4]];
  const double olen = (o1 - o0).norm();
  const Eigen::Vector2d ou = olen > 0.0 ? Eigen::Vector2d((o1 - o0) / olen) : Eigen::Vector2d(-u);
  // The adjacent sides' directions (from a to corner j + 3, from b to corner
  // j + 2), once for the loop: the same values at every vertex.
  const bool to_o1 = (o1 - a).norm() > 0.0, to_o0 = (o0 - b).norm() > 0.0;
  const Eigen::Vector2d u1 = to_o1 ? Eigen::Vector2d((o1 - a).normalized()) : Eigen::Vector2d::Zero();
  const Eigen::Vector2d u0 = to_o0 ? Eigen::Vector2d((o0 - b).normalized()) : Eigen::Vector2d::Zero();
  double pinch = 1.0, out = 0.0;
  for (std::size_t i = v.i0; i < v.i1; ++i) {
    const Eigen::Vector2d p = c.vertex(i);
    const double d = cross(u, p - a);  // > 0: inside the patch (left of a -> b)
    if (d <= 0.0) {
      out = std::max(out, -d);
      continue;
    }
    const Eigen::Vector2d f = a + u.dot(p - a) * u;
    const double full = cross(ou, f - o0), left = cross(ou, p - o0);
    pinch = std::min(pinch, full > 0.0 ? left / full : 0.0);
    // Towards an adjacent side: the sine of the angle at its corner between
    // that side and the direction to p (the corner as the map sees it on p's
    // scale; a vertex on the chord gives the corner's own sine).
    const double pa = (p - a).norm(), pb = (p - b).norm();
    if (pa > 0.0 && to_o1) pinch = std::min(pinch, cross(p - a, u1) / pa);
    if (pb > 0.0 && to_o0) pinch = std::min(pinch, cross(u0, p - b) / pb);
  }
  return std::min(pinch, 1.0 - 0.5 * out / chord);
}

LayoutCornerQuality LayoutQuality::quad(const LayoutMesh& m, const LayoutTopology& t, int q) const {
  LayoutCornerQuality w{1.0, 1.0};
  for (int j = 0; j < 4; ++j) {
    const LayoutCornerQuality c = corner(m, t, q, j);
    w.mean_ratio = std::min(w.mean_ratio, c.mean_ratio);
    w.scaled_jacobian = std::min(w.scaled_jacobian, c.scaled_jacobian);
    const double k = side_kinks(m, t, q, j);
    w.mean_ratio = std::min(w.mean_ratio, k);
    w.scaled_jacobian = std::min(w.scaled_jacobian, k);
  }
  return w;
}

}  // namespace tspline
