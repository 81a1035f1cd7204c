// Cubic T-spline blending functions on a balanced quadtree T-mesh
// (Brovka 2013 Sect. 5.2, Eq. 6). See tspline_basis.h for the definitions.
#include "tspline/spline/tspline_basis.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include "toolkit/errors.h"

namespace tspline {

namespace {

using I64 = std::int64_t;
constexpr I64 kRoot = TMesh::kRoot;

double to_param(I64 k) { return static_cast<double>(k) / static_cast<double>(kRoot); }

// ----------------------------------------------------------------------------
// Ray casting with exact integer coordinates.
//
// A ray along the horizontal line eta = e starting at xi = x, going right:
// the leaves just above and just below the ray right of x are found with
// leaf_at_doubled(2x+1, 2e+1) and leaf_at_doubled(2x+1, 2e-1). If e lies inside
// a cell both queries return that cell; if e lies on a horizontal cell line they
// are the cells on either side; on the border of the square one of them is -1.
// The next vertical line crossed is the nearer of their right edges: between x
// and that abscissa both leaves cover the ray, so no vertical edge touches it,
// and the nearer right edge is a cell edge that contains (x', e).
// ----------------------------------------------------------------------------
struct RayCaster {
  const TMesh& m;

  // Next vertical mesh line crossed by the ray eta = e from x in direction dir (+1/-1).
  // Returns x itself if x is on the border in that direction (the knot repeats).
  I64 next_x(I64 x, I64 e, int dir) const {
    if ((dir > 0 && x >= kRoot) || (dir < 0 && x <= 0)) return x;
    const I64 px = 2 * x + dir;
    I64 best = dir > 0 ? kRoot : 0;
    for (int s = -1; s <= 1; s += 2) {
      const int n = m.leaf_at_doubled(px, 2 * e + s);
      if (n < 0) continue;
      const QuadNode& q = m.node(n);
      best = dir > 0 ? std::min(best, TMesh::node_max(q).x) : std::max(best, TMesh::node_min(q).x);
    }
    return best;
  }
  // Next horizontal mesh line crossed by the ray xi = x from e in direction dir.
  I64 next_y(I64 x, I64 e, int dir) const {
    if ((dir > 0 && e >= kRoot) || (dir < 0 && e <= 0)) return e;
    const I64 py = 2 * e + dir;
    I64 best = dir > 0 ? kRoot : 0;
    for (int s = -1; s <= 1; s += 2) {
      const int n = m.leaf_at_doubled(2 * x + s, py);
      if (n < 0) continue;
      const QuadNode& q = m.node(n);
      best = dir > 0 ? std::min(best, TMesh::node_max(q).y) : std::max(best, TMesh::node_min(q).y);
    }
    return best;
  }
  // Local knot vector {k0, k1, c, k3, k4} of the anchor coordinate c (Sect. 5.2):
  // two crossings on each side; rays leaving the square repeat the border knot.
  std::array<I64, 5> knots_x(I64 x, I64 e) const {
    const I64 r1 = next_x(x, e, +1), r2 = next_x(r1, e, +1);
    const I64 l1 = next_x(x, e, -1), l2 = next_x(l1, e, -1);
    return {l2, l1, x, r1, r2};
  }
  std::array<I64, 5> knots_y(I64 x, I64 e) const {
    const I64 r1 = next_y(x, e, +1), r2 = next_y(x, r1, +1);
    const I64 l1 = next_y(x, e, -1), l2 = next_y(x, l1, -1);
    return {l2, l1, e, r1, r2};
  }
};

// Variants of an anchor knot vector in one direction (open knot structure).
// An interior anchor has one variant. An anchor on the border 0 has the ray
// vector {0,0,0,t1,t2}; its Anchor function uses 4 repeated knots {0,0,0,0,t1}
// (interpolating the border) and the extra function keeps {0,0,0,t1,t2}
// (exactly three repeated knots). Symmetrically at 1.
struct DirectionVariants {
  std::array<I64, 5> anchor;
  bool has_extra = false;
  std::array<I64, 5> extra{};
  double extra_point = 0.0;  // midpoint of the first inner knot span (Fig. 8 xi^e)
};

DirectionVariants variants(const std::array<I64, 5>& k) {
  DirectionVariants v{k};
  if (k[2] == 0) {
    v.anchor = {0, 0, 0, 0, k[3]};
    v.has_extra = true;
    v.extra = k;
    v.extra_point = 0.5 * to_param(k[3]);
  } else if (k[2] == kRoot) {
    v.anchor = {k[1], kRoot, kRoot, kRoot, kRoot};
    v.has_extra = true;
    v.extra = k;
    v.extra_point = 0.5 * (to_param(k[1]) + 1.0);
  }
  return v;
}

std::array<double, 5> to_param(const std::array<I64, 5>& k) {
  std::array<double, 5> d;
  for (int i = 0; i < 5; ++i) d[i] = to_param(k[i]);
  return d;
}

// Division with the B-spline convention 0/0 := 0 (a zero-length span).
inline double ratio(double a, double b) { return b == 0.0 ? 0.0 : a / b; }

}  // namespace

// ----------------------------------------------------------------------------
// Cubic B-spline on 5 knots by the Cox-de Boor recursion (Sect. 5.1) restricted
// to the knot span containing t; derivatives by the standard formula
//   N'_{i,p} = p (N_{i,p-1} / (k_{i+p} - k_i) - N_{i+1,p-1} / (k_{i+p+1} - k_{i+1})),
// applied twice for N''.
// ----------------------------------------------------------------------------
double cubic_bspline(const std::array<double, 5>& k, double t, double* d1, double* d2) {
  if (d1) *d1 = 0.0;
  if (d2) *d2 = 0.0;
  if (!(t >= k[0] && t <= k[4]) || k[0] == k[4]) return 0.0;
  int span = -1;
  if (t == k[4]) {
    if (k[4] != 1.0) return 0.0;  // right-continuous: 0 at the right end of the support
    for (int i = 3; i >= 0; --i)  // left limit at the border: last non-empty span
      if (k[i] < k[i + 1]) {
        span = i;
        break;
      }
  } else {
    for (int i = 0; i < 4; ++i)
      if (k[i] <= t && t < k[i + 1]) {
        span = i;
        break;
      }
  }
  if (span < 0) return 0.0;
  // Degree 0..3 functions N_{j,p}, j = 0..3-p, on the knots k[j..j+p+1].
  double n0[4] = {0, 0, 0, 0};
  n0[span] = 1.0;
  double n1[3], n2[2];
  for (int j = 0; j < 3; ++j)
    n1[j] = ratio(t - k[j], k[j + 1] - k[j]) * n0[j] + ratio(k[j + 2] - t, k[j + 2] - k[j + 1]) * n0[j + 1];
  for (int j = 0; j < 2; ++j)
    n2[j] = ratio(t - k[j], k[j + 2] - k[j]) * n1[j] + ratio(k[j + 3] - t, k[j + 3] - k[j + 1]) * n1[j + 1];
  const double n3 = ratio(t - k[0], k[3] - k[0]) * n2[0] + ratio(k[4] - t, k[4] - k[1]) * n2[1];
  if (d1) *d1 = 3.0 * (ratio(n2[0], k[3] - k[0]) - ratio(n2[1], k[4] - k[1]));
  if (d2) {
    // Derivatives of the two quadratic pieces, then of the cubic.
    const double dn2_0 = 2.0 * (ratio(n1[0], k[2] - k[0]) - ratio(n1[1], k[3] - k[1]));
    const double dn2_1 = 2.0 * (ratio(n1[1], k[3] - k[1]) - ratio(n1[2], k[4] - k[2]));
    *d2 = 3.0 * (ratio(dn2_0, k[3] - k[0]) - ratio(dn2_1, k[4] - k[1]));
  }
  return n3;
}

bool cubic_bspline_vanishes(const std::array<double, 5>& k, double t) {
  return !(t >= k[0] && t <= k[4]) || k[0] == k[4] || (t == k[4] && k[4] != 1.0) ||
         (t == k[0] && k[3] > k[0]);
}

TSplineBasis::TSplineBasis(const TMesh& mesh) : mesh_(&mesh) {
  if (!mesh.has_topology()) throw toolkit::InternalError("TSplineBasis: the T-mesh has no topology");
  const RayCaster rays{mesh};
  const std::size_t nv = mesh.num_vertices();
  functions_.reserve(nv + 4 * static_cast<std::size_t>(std::sqrt(static_cast<double>(nv))) + 16);
  // Integer knots for the support lists (exact).
  std::vector<std::array<I64, 4>> boxes;  // x0, x4, y0, y4
  boxes.reserve(functions_.capacity());
  auto add = [&](const std::array<I64, 5>& kx, const std::array<I64, 5>& ky, int v, BlendingFunction::Kind kind,
                 const Eigen::Vector2d& point) {
    BlendingFunction f;
    f.knots_xi = to_param(kx);
    f.knots_eta = to_param(ky);
    f.vertex = v;
    f.kind = kind;
    f.interpolation_point = point;
    functions_.push_back(f);
    boxes.push_back({kx[0], kx[4], ky[0], ky[4]});
  };
  using Kind = BlendingFunction::Kind;
  for (std::size_t vi = 0; vi < nv; ++vi) {
    const int v = static_cast<int>(vi);
    const IPoint p = mesh.vertex_ipos(v);
    const DirectionVariants vx = variants(rays.knots_x(p.x, p.y));
    const DirectionVariants vy = variants(rays.knots_y(p.x, p.y));
    const Eigen::Vector2d a = mesh.vertex_param(v);
    add(vx.anchor, vy.anchor, v, Kind::Anchor, a);
    // Border vertex: three repeated knots across the border it lies on; at a
    // corner one such function per side plus one with three repeated knots in
    // both directions (its interpolation point is the corner cell's centre).
    if (vx.has_extra) add(vx.extra, vy.anchor, v, Kind::EdgeExtra, {vx.extra_point, a.y()});
    if (vy.has_extra) add(vx.anchor, vy.extra, v, Kind::EdgeExtra, {a.x(), vy.extra_point});
    if (vx.has_extra && vy.has_extra) add(vx.extra, vy.extra, v, Kind::CornerExtra, {vx.extra_point, vy.extra_point});
  }

  // Support lists: descend the quadtree over the nodes whose box meets the open
  // support box (x0, x4) x (y0, y4). Functions are visited in increasing order,
  // so every list comes out sorted. Two passes: count, then fill.
  const std::size_t nc = mesh.num_cells();
  cell_functions_.assign(nc, {});
  std::vector<int> counts(nc, 0);
  std::vector<int> stack;
  auto visit = [&](const std::array<I64, 4>& b, auto&& on_leaf) {
    stack.assign(1, 0);
    while (!stack.empty()) {
      const int n = stack.back();
      stack.pop_back();
      const QuadNode& q = mesh.node(n);
      const IPoint lo = TMesh::node_min(q), hi = TMesh::node_max(q);
      if (lo.x >= b[1] || hi.x <= b[0] || lo.y >= b[3] || hi.y <= b[2]) continue;
      if (q.is_leaf()) {
        on_leaf(mesh.cell_of_node(n));
      } else {
        for (int k = 0; k < 4; ++k) stack.push_back(q.first_child + k);
      }
    }
  };
  for (const auto& b : boxes) visit(b, [&](int c) { ++counts[c]; });
  for (std::size_t c = 0; c < nc; ++c) cell_functions_[c].reserve(counts[c]);
  for (std::size_t a = 0; a < boxes.size(); ++a)
    visit(boxes[a], [&](int c) { cell_functions_[c].push_back(static_cast<int>(a)); });
}

int TSplineBasis::locate(const Eigen::Vector2d& uv) const {
  if (!(uv.x() >= 0.0 && uv.x() <= 1.0 && uv.y() >= 0.0 && uv.y() <= 1.0))
    throw toolkit::InputError("TSplineBasis::locate: point outside [0,1]^2");
  // uv * kRoot is exact (power of two); floor picks the cell to the right/above
  // of a cell line; clamping puts xi = 1 (eta = 1) in the last cell.
  auto cell_index = [](double t) {
    const I64 i = static_cast<I64>(std::floor(t * static_cast<double>(kRoot)));
    return std::clamp<I64>(i, 0, kRoot - 1);
  };
  const int n = mesh_->leaf_at_doubled(2 * cell_index(uv.x()) + 1, 2 * cell_index(uv.y()) + 1);
  return mesh_->cell_of_node(n);
}

void TSplineBasis::evaluate(const Eigen::Vector2d& uv, BasisValues& out, int order) const {
  evaluate(locate(uv), uv, out, order);
}

// R_a = N_a / S, S = sum_b N_b (Eq. 6). Quotient rule, with R = N/S:
//   R_i  = (N_i - R S_i) / S
//   R_ij = (N_ij - R_i S_j - R_j S_i - R S_ij) / S
// (differentiate N = R S twice: N_ij = R_ij S + R_i S_j + R_j S_i + R S_ij).
void TSplineBasis::evaluate(int c, const Eigen::Vector2d& uv, BasisValues& out, int order) const {
  if (order < 0 || order > 2) throw toolkit::InputError("TSplineBasis::evaluate: order must be 0, 1 or 2");
  const std::vector<int>& ids = cell_functions_.at(static_cast<std::size_t>(c));
  const std::size_t n = ids.size();
  out.ids = ids;
  out.R.resize(n);
  const bool d1 = order >= 1, d2 = order >= 2;
  out.R_xi.resize(d1 ? n : 0);
  out.R_eta.resize(d1 ? n : 0);
  out.R_xixi.resize(d2 ? n : 0);
  out.R_xieta.resize(d2 ? n : 0);
  out.R_etaeta.resize(d2 ? n : 0);
  double S = 0, Sx = 0, Sy = 0, Sxx = 0, Sxy = 0, Syy = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const BlendingFunction& f = functions_[ids[k]];
    // Values only: a factor known to be +0 makes N = +0 (the other factor is
    // finite), which adds nothing to S. Most of a cell's functions vanish so
    // at points on its edges (interface gaps, interpolation at vertices).
    if (!d1 && (cubic_bspline_vanishes(f.knots_xi, uv.x()) || cubic_bspline_vanishes(f.knots_eta, uv.y()))) {
      out.R[k] = 0.0;
      continue;
    }
    double u1 = 0, u2 = 0, w1 = 0, w2 = 0;
    const double u = cubic_bspline(f.knots_xi, uv.x(), d1 ? &u1 : nullptr, d2 ? &u2 : nullptr);
    const double w = cubic_bspline(f.knots_eta, uv.y(), d1 ? &w1 : nullptr, d2 ? &w2 : nullptr);
    // Product rule for N = u(xi) w(eta); store N and its derivatives for now.
    out.R[k] = u * w;
    S += u * w;
    if (d1) {
      out.R_xi[k] = u1 * w;
      out.R_eta[k] = u * w1;
      Sx += u1 * w;
      Sy += u * w1;
    }
    if (d2) {
      out.R_xixi[k] = u2 * w;
      out.R_xieta[k] = u1 * w1;
      out.R_etaeta[k] = u * w2;
      Sxx += u2 * w;
      Sxy += u1 * w1;
      Syy += u * w2;
    }
  }
  if (!(S > 0.0)) throw toolkit::InternalError("TSplineBasis::evaluate: the blending functions vanish at the point");
  const double inv = 1.0 / S;
  for (std::size_t k = 0; k < n; ++k) {
    const double R = out.R[k] * inv;
    out.R[k] = R;
    if (!d1) continue;
    const double Rx = (out.R_xi[k] - R * Sx) * inv;
    const double Ry = (out.R_eta[k] - R * Sy) * inv;
    out.R_xi[k] = Rx;
    out.R_eta[k] = Ry;
    if (!d2) continue;
    out.R_xixi[k] = (out.R_xixi[k] - 2.0 * Rx * Sx - R * Sxx) * inv;
    out.R_xieta[k] = (out.R_xieta[k] - Rx * Sy - Ry * Sx - R * Sxy) * inv;
    out.R_etaeta[k] = (out.R_etaeta[k] - 2.0 * Ry * Sy - R * Syy) * inv;
  }
}

bool touches_border(const BlendingFunction& f) {
  auto open_end = [](const std::array<double, 5>& k) {
    return (k[0] == 0.0 && k[3] == 0.0) || (k[1] == 1.0 && k[4] == 1.0);
  };
  return open_end(f.knots_xi) || open_end(f.knots_eta);
}

}  // namespace tspline
