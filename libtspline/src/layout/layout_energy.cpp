// The layout optimizer's energy (layout_energy.h).
#include "tspline/layout/layout_energy.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "tspline/boundary/plane.h"

namespace tspline {
namespace {

// x^p, by multiplication for the powers used (std::pow was a seventh of the layout's time).
double power(double x, double p) {
  if (p == 1.0) return x;
  if (p == 4.0) {
    const double x2 = x * x;
    return x2 * x2;
  }
  return std::pow(x, p);
}

// A corner's side vectors (e1, e2) at each of LayoutQuality::corner_scales.
using CornerVectors = std::array<std::pair<Eigen::Vector2d, Eigen::Vector2d>, LayoutQuality::corner_scales.size()>;

// The term of a corner with the given vectors at its first `scales` scales:
// the worst over the scales of (|e1| + |e2|)^2 / (2 chi(det)), to the power p;
// infinite for a degenerate corner, and with `barrier` for an inverted one.
// The regularized term alone is not a barrier: an inverted corner costs about
// 8 sin / eps_rel (1e9 at eps_rel = 1e-4), less than a pinched side's
// 2 / 1e-9, so a quality sweep could trade a pinched side for a fold, which
// the untangling then could not undo (Corsica: the worst corner fell from 0.27
// to -0.95 in one sweep, and 60 sweeps of untangling left it at -0.86).
using CornerNorms = std::array<std::pair<double, double>, LayoutQuality::corner_scales.size()>;

// corner_term with the vectors' lengths given (|e1|, |e2| per scale: the same values).
double corner_term(const CornerVectors& vectors, const CornerNorms& norms, int scales, double p,
                   double eps_rel, bool barrier) {
  double e = 0.0;  // the worst over the scales
  for (int k = 0; k < scales; ++k) {
    const auto& [e1, e2] = vectors[k];
    const double det = cross(e1, e2);
    const auto [n1, n2] = norms[k];
    const double s = n1 + n2;
    if (!(n1 > 0.0 && n2 > 0.0) || (barrier && !(det > 0.0))) return std::numeric_limits<double>::infinity();
    const double eps = eps_rel * n1 * n2;
    const double chi = 0.5 * (det + std::sqrt(eps * eps + det * det));
    e = std::max(e, s * s / (2.0 * chi));
  }
  return power(e, p);
}

double corner_term(const CornerVectors& vectors, int scales, double p, double eps_rel, bool barrier) {
  CornerNorms norms;
  for (int k = 0; k < scales; ++k) norms[k] = {vectors[k].first.norm(), vectors[k].second.norm()};
  return corner_term(vectors, norms, scales, p, eps_rel, barrier);
}

// The term of corner j of quad q.
double corner_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int q, int j, double p,
                     double eps_rel, bool barrier) {
  CornerVectors vectors;
  const int scales = Q.corner_vectors_at(m, t, q, j, LayoutQuality::corner_scales, vectors.data());
  return corner_term(vectors, scales, p, eps_rel, barrier);
}

// The term of a side of kink figure k (0 for a cut or a side without kinks).
double kink_term(double k, double p) { return k < 1.0 ? power(2.0 / std::max(k, 1e-9), p) : 0.0; }

// The term of side j's kinks.
double kink_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int q, int j, double p) {
  return kink_term(Q.side_kinks(m, t, q, j), p);
}

// The term of a side of shape figure g (0 for a cut or a side that keeps its shape).
double shape_term(double g, double p) { return g < 1.0 ? power(2.0 / std::max(g, 1e-9), p) : 0.0; }

// The term of side j's shape.
double shape_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int q, int j, double p) {
  return shape_term(Q.side_shape(m, t, q, j), p);
}

}  // namespace

double layout_quad_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int q, double p,
                          double eps_rel, bool barrier) {
  double sum = 0.0;
  for (int j = 0; j < 4; ++j) {
    const double e = corner_energy(m, t, Q, q, j, p, eps_rel, barrier);
    if (!std::isfinite(e)) return e;
    sum += e + kink_energy(m, t, Q, q, j, p) + shape_energy(m, t, Q, q, j, p);
  }
  return sum;
}

double layout_node_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n, double p,
                          double eps_rel, bool barrier) {
  double sum = 0.0;
  for (const auto& [q, j] : t.corners_of(n)) sum += layout_quad_energy(m, t, Q, q, p, eps_rel, barrier);
  return sum;
}

double layout_moving_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n, double p,
                            double eps_rel, bool barrier, double stop_at) {
  // Every term is positive: the sum only grows.
  double sum = 0.0;
  const bool on_ring = m.ring[n] >= 0;
  for (const auto& [q, j] : t.corners_of(n)) {
    for (const int k : {0, 1, 3}) {
      const double e = corner_energy(m, t, Q, q, (j + k) % 4, p, eps_rel, barrier);
      if (!std::isfinite(e)) return e;
      sum += e;
      if (sum >= stop_at) return sum;
    }
    sum += shape_energy(m, t, Q, q, (j + 1) % 4, p) + shape_energy(m, t, Q, q, (j + 2) % 4, p);
    if (on_ring)
      for (const int k : {0, 3}) {
        const int side = (j + k) % 4;
        sum += kink_energy(m, t, Q, q, side, p) + shape_energy(m, t, Q, q, side, p);
      }
    if (sum >= stop_at) return sum;
  }
  return sum;
}

LayoutMovingEnergy::LayoutMovingEnergy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n,
                                       double p, double eps_rel, bool barrier)
    : m_(m), t_(t), Q_(Q), n_(n), p_(p), eps_rel_(eps_rel), barrier_(barrier) {
  // At corners j +- 1 whose side to n is a cut (every side of an inner n),
  // that side is x[n] - x[v] at every scale and the other side is the same
  // wherever n goes (as corner_vectors_at gives it, at each scale). Where the
  // side to n runs along a ring (ring n), the corner is computed afresh.
  for (const auto& [q, j] : t.corners_of(n))
    for (const int k : {1, 3}) {
      Neighbour c;
      c.node = m.quads[q][(j + k) % 4];
      c.n_is_next = k == 3;  // corner j - 1's next corner is n
      const int side_to_n = k == 3 ? (j + 3) % 4 : j;
      c.fresh = m.ring[c.node] >= 0 && m.ring[n] == m.ring[c.node] && t.on_ring(q, side_to_n);
      if (!c.fresh) {
        CornerVectors v;
        c.scales = Q.corner_vectors_at(m, t, q, (j + k) % 4, LayoutQuality::corner_scales, v.data());
        for (int s = 0; s < c.scales; ++s) {
          c.fixed[s] = c.n_is_next ? v[s].second : v[s].first;
          c.fixed_norm[s] = c.fixed[s].norm();
        }
      }
      if (m.ring[n] < 0) {
        const auto known = std::find(edge_nodes_.begin(), edge_nodes_.end(), c.node);
        c.edge = static_cast<int>(known - edge_nodes_.begin());
        if (known == edge_nodes_.end()) edge_nodes_.push_back(c.node);
      }
      neighbours_.push_back(c);
    }
  for (const auto& [q, j] : t.corners_of(n))
    for (const int k : {1, 2}) far_sides_.push_back(Q.side_vertices(m, t, q, (j + k) % 4));
}

double LayoutMovingEnergy::operator()(double stop_at) const {
  // The terms of layout_moving_energy, in its order (the same sums).
  double sum = 0.0;
  const bool on_ring = m_.ring[n_] >= 0;
  std::size_t at = 0, side = 0;
  CornerVectors v;
  CornerNorms norms;
  // At an inner n, each cut's vectors (from n, and to n) and length, once:
  // the same operations on the same values as corner_vectors_at and
  // corner_term make them, so the same sums.
  constexpr std::size_t kEdges = 16;
  std::array<Eigen::Vector2d, kEdges> from_n, to_n_of;
  std::array<double, kEdges> length;
  const bool cached = !edge_nodes_.empty() && edge_nodes_.size() <= kEdges;
  if (cached)
    for (std::size_t i = 0; i < edge_nodes_.size(); ++i) {
      const Eigen::Vector2d& x = m_.x[n_];
      const Eigen::Vector2d& y = m_.x[edge_nodes_[i]];
      from_n[i] = y - x, to_n_of[i] = x - y;
      length[i] = from_n[i].norm();
    }
  for (const auto& [q, j] : t_.corners_of(n_)) {
    for (const int k : {0, 1, 3}) {
      double e;
      if (k == 0) {
        if (cached) {  // an inner corner: one scale, its sides to corners j + 1 and j - 1
          const int a = neighbours_[at].edge, b = neighbours_[at + 1].edge;
          v[0] = {from_n[a], from_n[b]};
          norms[0] = {length[a], length[b]};
          e = corner_term(v, norms, 1, p_, eps_rel_, barrier_);
        } else {
          e = corner_energy(m_, t_, Q_, q, j, p_, eps_rel_, barrier_);
        }
      } else if (const Neighbour& c = neighbours_[at++]; c.fresh) {
        e = corner_energy(m_, t_, Q_, q, (j + k) % 4, p_, eps_rel_, barrier_);
      } else {
        const Eigen::Vector2d to_n = cached ? to_n_of[c.edge] : Eigen::Vector2d(m_.x[n_] - m_.x[c.node]);
        const double to_n_norm = cached ? length[c.edge] : to_n.norm();
        for (int s = 0; s < c.scales; ++s) {
          v[s] = c.n_is_next ? std::pair{to_n, c.fixed[s]} : std::pair{c.fixed[s], to_n};
          norms[s] =
              c.n_is_next ? std::pair{to_n_norm, c.fixed_norm[s]} : std::pair{c.fixed_norm[s], to_n_norm};
        }
        e = corner_term(v, norms, c.scales, p_, eps_rel_, barrier_);
      }
      if (!std::isfinite(e)) return e;
      sum += e;
      if (sum >= stop_at) return sum;
    }
    const double next_side = shape_term(Q_.side_shape(m_, q, (j + 1) % 4, far_sides_[side]), p_);
    const double far_side = shape_term(Q_.side_shape(m_, q, (j + 2) % 4, far_sides_[side + 1]), p_);
    side += 2;
    sum += next_side + far_side;
    if (on_ring)
      for (const int k : {0, 3}) {
        const int ring_side = (j + k) % 4;
        // (The side's ring vertices once for both terms: the same values.)
        const LayoutQuality::SideVertices sv = Q_.side_vertices(m_, t_, q, ring_side);
        sum += kink_term(Q_.side_kinks(sv), p_) + shape_term(Q_.side_shape(m_, q, ring_side, sv), p_);
      }
    if (sum >= stop_at) return sum;
  }
  return sum;
}

}  // namespace tspline
