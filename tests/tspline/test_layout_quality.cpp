// The layout's own figures and moves (layout/layout_quality.h,
// layout_optimizer.h, layout_topology.h): corner J_r and scaled Jacobian
// against their closed forms, side kinks against sin^2(phi / 2), the node
// optimizer bringing displaced and inverted nodes back, an edge rotation that
// replaces a long diagonal, and the pillow layer on a ring with a flat corner.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <tuple>

#include "test_support.h"
#include "tspline/boundary/domain.h"
#include "tspline/boundary/plane.h"
#include "tspline/errors.h"
#include "tspline/layout/layout_energy.h"
#include "tspline/layout/layout_mesh.h"
#include "tspline/layout/layout_optimizer.h"
#include "tspline/layout/layout_quality.h"
#include "tspline/layout/layout_topology.h"
#include "tspline/layout/ring_geometry.h"
#include "tspline/layout/ring_nodes.h"
#include "tspline/multipatch/patch_layout.h"

namespace {

using V = Eigen::Vector2d;

// The signed area of quad q of m with straight sides (> 0: counter-clockwise).
double quad_area(const tspline::LayoutMesh& m, const std::array<int, 4>& q) {
  return tspline::signed_area(std::vector<V>{m.x[q[0]], m.x[q[1]], m.x[q[2]], m.x[q[3]]});
}

// A layout whose nodes are the given ring vertices (ring 0, arc lengths along
// it) followed by inner nodes.
tspline::LayoutMesh ring_mesh(const tspline::RingCurve& ring, const std::vector<V>& ring_points,
                              const std::vector<V>& inner, const std::vector<std::array<int, 4>>& quads) {
  tspline::LayoutMesh m;
  for (const V& p : ring_points) {
    m.x.push_back(p);
    m.ring.push_back(0);
    // The arc length of a point on the ring: the nearest vertex's or along an edge.
    double arc = 0.0, best = 1e300;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const V a = ring.vertex(i), b = ring.vertex(i + 1);
      const double len = (b - a).norm();
      const double t = std::clamp((p - a).dot(b - a) / (len * len), 0.0, 1.0);
      const double d = (a + t * (b - a) - p).norm();
      if (d < best) best = d, arc = ring.arc(i) + t * len;
    }
    m.arc.push_back(arc);
  }
  for (const V& p : inner) {
    m.x.push_back(p);
    m.ring.push_back(-1);
    m.arc.push_back(0.0);
  }
  m.quads = quads;
  return m;
}

tspline::LayoutRings one_ring(const std::vector<V>& vertices) {
  tspline::LayoutRings r;
  r.curves.emplace_back(vertices);
  return r;
}

std::vector<V> vertices_of(const tspline::RingCurve& ring) {
  std::vector<V> v;
  for (std::size_t i = 0; i < ring.size(); ++i) v.push_back(ring.vertex(i));
  return v;
}

const tspline::LayoutAdmissible anywhere = [](const tspline::LayoutMesh&, const tspline::LayoutTopology&, int) {
  return true;
};

// The unit square as 2 x 2 quads: eight ring nodes, the centre (node 8) inside.
// A 20 x 20 grid of the unit square with its inner nodes sheared in rows:
// many poor quads all over, so that batches of tries (rotations) and of node
// moves hold many.
tspline::LayoutMesh sheared_grid(const tspline::LayoutRings& ring) {
  const int n = 20;
  std::vector<V> on_ring, inner;
  std::vector<int> id((n + 1) * (n + 1), -1);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      if (i == 0 || j == 0 || i == n || j == n) id[i + (n + 1) * j] = 1;
  // Ring nodes counter-clockwise from (0, 0), then inner nodes row by row.
  std::vector<std::array<int, 2>> walk;
  for (int i = 0; i < n; ++i) walk.push_back({i, 0});
  for (int j = 0; j < n; ++j) walk.push_back({n, j});
  for (int i = n; i > 0; --i) walk.push_back({i, n});
  for (int j = n; j > 0; --j) walk.push_back({0, j});
  for (const auto& [i, j] : walk)
    id[i + (n + 1) * j] = static_cast<int>(on_ring.size()), on_ring.push_back(V(i, j) / n);
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) {
      id[i + (n + 1) * j] = static_cast<int>(4 * n + inner.size());
      // Sheared on the left; on the right rows pushed alternately left and
      // right: poor quads that no rotation helps, far from those that one
      // does (the later rounds find their tries' nodes unchanged).
      const double shear = i < n / 2 ? (j % 3 == 1 ? 0.45 : -0.2) * std::sin(0.7 * i * j) : 0.0;
      const double push = i > n / 2 + 1 ? (j % 2 == 0 ? 0.3 : -0.3) : 0.0;
      inner.push_back(V(i + shear + push, j + 0.3 * shear) / n);
    }
  std::vector<std::array<int, 4>> quads;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      quads.push_back({id[i + (n + 1) * j], id[i + 1 + (n + 1) * j], id[i + 1 + (n + 1) * (j + 1)],
                       id[i + (n + 1) * (j + 1)]});
  return ring_mesh(ring.curves[0], on_ring, inner, quads);
}

tspline::LayoutMesh square_2x2(const tspline::RingCurve& ring, const V& centre, double bottom_mid) {
  return ring_mesh(ring,
                   {V(0, 0), V(bottom_mid, 0), V(1, 0), V(1, 0.5), V(1, 1), V(0.5, 1), V(0, 1), V(0, 0.5)},
                   {centre}, {{0, 1, 8, 7}, {1, 2, 3, 8}, {8, 3, 4, 5}, {7, 8, 5, 6}});
}

}  // namespace

TEST_SUITE("layout_quality") {
  TEST_CASE("corner figures: J_r = 2 sin(theta) L1 L2 / (L1^2 + L2^2) and SJ = sin(theta), from the sides") {
    // A 2 x 1 rectangle as one patch: right angles, sides 2 and 1 at every corner.
    const tspline::LayoutRings rect = one_ring({V(0, 0), V(2, 0), V(2, 1), V(0, 1)});
    const tspline::LayoutMesh m = ring_mesh(rect.curves[0], vertices_of(rect.curves[0]), {}, {{0, 1, 2, 3}});
    const tspline::LayoutTopology t(m);
    const tspline::LayoutQuality Q(rect);
    for (int j = 0; j < 4; ++j) {
      const tspline::LayoutCornerQuality c = Q.corner(m, t, 0, j);
      CHECK(c.scaled_jacobian == doctest::Approx(1.0));
      CHECK(c.mean_ratio == doctest::Approx(2.0 * 2.0 * 1.0 / (4.0 + 1.0)));
      CHECK(Q.side_kinks(m, t, 0, j) == 1.0);
    }
    CHECK(Q.side_length(m, t, 0, 0) == doctest::Approx(2.0));
    // A rhombus of side 1 and angle 60 degrees: J_r = SJ = sin 60 at the acute corners.
    const double c60 = 0.5, s60 = std::sqrt(3.0) / 2.0;
    const tspline::LayoutRings rh = one_ring({V(0, 0), V(1, 0), V(1 + c60, s60), V(c60, s60)});
    const tspline::LayoutMesh r = ring_mesh(rh.curves[0], vertices_of(rh.curves[0]), {}, {{0, 1, 2, 3}});
    const tspline::LayoutTopology rt(r);
    const tspline::LayoutQuality RQ(rh);
    CHECK(RQ.corner(r, rt, 0, 0).mean_ratio == doctest::Approx(s60));
    CHECK(RQ.corner(r, rt, 0, 1).scaled_jacobian == doctest::Approx(s60));  // 120 degrees: sin 120 = sin 60
    CHECK(RQ.quad(r, rt, 0).mean_ratio == doctest::Approx(s60));
  }

  TEST_CASE("patch corners in range: 1 to 170 degrees, counter-clockwise from the first side") {
    auto at = [](double degrees) {
      const double a = degrees * std::numbers::pi / 180.0;
      return tspline::patch_corner_in_range(V(2, 0), V(3 * std::cos(a), 3 * std::sin(a)));
    };
    CHECK(at(90.0));
    CHECK(at(1.5));
    CHECK(at(165.0));
    CHECK_FALSE(at(0.5));    // a needle
    CHECK_FALSE(at(175.0));  // nearly flat: det J ~ 0 at the corner
    CHECK_FALSE(at(180.0));
    CHECK_FALSE(at(200.0));  // reflex
    CHECK_FALSE(at(270.0));
    CHECK_FALSE(tspline::patch_corner_in_range(V(0, 0), V(1, 0)));  // a side of length 0
    // A narrower range: up to 135 degrees (sin 45 = 0.7071 rounded up to 0.708).
    auto at_most_135 = [](double degrees) {
      const double a = degrees * std::numbers::pi / 180.0;
      return tspline::patch_corner_in_range(V(2, 0), V(3 * std::cos(a), 3 * std::sin(a)), 135.0);
    };
    CHECK(at_most_135(134.0));
    CHECK_FALSE(at_most_135(136.0));
    CHECK(tspline::obtuse_corner_sine(170.0) == 0.174);  // the check's own threshold, sin 10 deg = 0.17365
    CHECK(tspline::obtuse_corner_sine(135.0) == 0.708);
    CHECK_THROWS_AS((void)tspline::obtuse_corner_sine(90.0), tspline::InputError);
    CHECK_THROWS_AS((void)tspline::obtuse_corner_sine(180.0), tspline::InputError);
    CHECK_THROWS_AS((void)tspline::obtuse_corner_sine(std::nan("")), tspline::InputError);
  }

  TEST_CASE("side kinks: a ring vertex inside a side with domain angle phi gives sin^2(phi / 2)") {
    // The bottom of a 2 x 1 rectangle bent down at (1, -d): the domain's angle there is
    // 180 - 2 atan(d), so sin^2(phi / 2) = cos^2(atan d) = 1 / (1 + d^2).
    for (const double d : {0.25, 1.0, 3.0}) {
      const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, -d), V(2, 0), V(2, 1), V(0, 1)});
      const tspline::LayoutMesh m =
          ring_mesh(ring.curves[0], {V(0, 0), V(2, 0), V(2, 1), V(0, 1)}, {}, {{0, 1, 2, 3}});
      const tspline::LayoutTopology t(m);
      const tspline::LayoutQuality Q(ring);
      CHECK(Q.side_kinks(m, t, 0, 0) == doctest::Approx(1.0 / (1.0 + d * d)));
      CHECK(Q.side_kinks(m, t, 0, 1) == 1.0);  // the right side is straight
      // The bottom side runs along the ring: its length is the arc's, 2 sqrt(1 + d^2).
      CHECK(Q.side_length(m, t, 0, 0) == doctest::Approx(2.0 * std::sqrt(1.0 + d * d)));
      CHECK(Q.quad(m, t, 0).mean_ratio <= 1.0 / (1.0 + d * d) + 1e-12);
    }
  }

  TEST_CASE("side shape: the width a coast bulging into the patch leaves, over the straight patch's") {
    // A 2 x 1 rectangle whose bottom rises to (1, d) inside: at the vertex the patch
    // is 1 - d wide where the straight patch is 1.
    for (const double d : {0.2, 0.6}) {
      const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, d), V(2, 0), V(2, 1), V(0, 1)});
      const tspline::LayoutMesh m =
          ring_mesh(ring.curves[0], {V(0, 0), V(2, 0), V(2, 1), V(0, 1)}, {}, {{0, 1, 2, 3}});
      const tspline::LayoutTopology t(m);
      const tspline::LayoutQuality Q(ring);
      CHECK(Q.side_shape(m, t, 0, 0) == doctest::Approx(1.0 - d));
      CHECK(Q.side_shape(m, t, 0, 1) == 1.0);  // straight
    }
    // A wedge-shaped patch, 4 long, 2 wide at x = 0 and 1 wide at x = 4, whose bottom
    // rises by 0.5 at x = 3: the width there is 1.25 - 0.5 of 1.25.
    const tspline::LayoutRings wedge = one_ring({V(0, 0), V(3, 0.5), V(4, 0), V(4, 1), V(0, 2)});
    const tspline::LayoutMesh w = ring_mesh(wedge.curves[0], {V(0, 0), V(4, 0), V(4, 1), V(0, 2)}, {}, {{0, 1, 2, 3}});
    const tspline::LayoutQuality WQ(wedge);
    // (Measured perpendicular to the opposite side: both widths scale alike.)
    CHECK(WQ.side_shape(w, tspline::LayoutTopology(w), 0, 0) == doctest::Approx(0.75 / 1.25));
    // A coast reaching towards an adjacent side: from the corner (2, 0) the vertex
    // (1.95, 0.8) is seen at the angle asin(0.05 / |(-0.05, 0.8)|) from the right side.
    const tspline::LayoutRings reach = one_ring({V(0, 0), V(1.95, 0.8), V(2, 0), V(2, 1), V(0, 1)});
    const tspline::LayoutMesh r =
        ring_mesh(reach.curves[0], {V(0, 0), V(2, 0), V(2, 1), V(0, 1)}, {}, {{0, 1, 2, 3}});
    CHECK(tspline::LayoutQuality(reach).side_shape(r, tspline::LayoutTopology(r), 0, 0) ==
          doctest::Approx(0.05 / std::hypot(0.05, 0.8)));
    // A coast bulging out of the patch by d_out over a chord c: 1 - d_out / (2 c).
    const tspline::LayoutRings outward = one_ring({V(0, 0), V(1, -0.5), V(2, 0), V(2, 1), V(0, 1)});
    const tspline::LayoutMesh o =
        ring_mesh(outward.curves[0], {V(0, 0), V(2, 0), V(2, 1), V(0, 1)}, {}, {{0, 1, 2, 3}});
    CHECK(tspline::LayoutQuality(outward).side_shape(o, tspline::LayoutTopology(o), 0, 0) ==
          doctest::Approx(1.0 - 0.5 * 0.5 / 2.0));
  }

  TEST_CASE("layout energy: a node's moving part differs from its whole energy by a constant, prepared or not") {
    // The 2 x 2 square with a kinked, bulging bottom coast (kinks and shapes in
    // play): wherever a node goes (inner: in the plane; ring: along its ring),
    // its energy minus its moving part stays the same, in both phases.
    const tspline::LayoutRings ring =
        one_ring({V(0, 0), V(0.2, 0.05), V(0.35, 0.0), V(0.7, 0.12), V(1, 0), V(1, 1), V(0.4, 0.93), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    const tspline::RingCurve& c = ring.curves[0];
    tspline::LayoutMesh m = square_2x2(c, V(0.55, 0.45), 0.5);
    for (std::size_t n = 0; n < 8; ++n) m.x[n] = c.point(m.arc[n]);  // on the ring itself
    const tspline::LayoutTopology t(m);
    int finite_moves = 0;
    for (const auto& [p, eps, barrier] : {std::tuple{1.0, 0.1, false}, std::tuple{4.0, 1e-4, true}}) {
      for (int n = 0; n < static_cast<int>(m.size()); ++n) {
        CAPTURE(n);
        CAPTURE(p);
        const tspline::LayoutMesh keep = m;
        // The whole energy and its part that stays (whole - moving).
        auto parts = [&] {
          const double whole = tspline::layout_node_energy(m, t, Q, n, p, eps, barrier);
          return std::pair{whole, whole - tspline::layout_moving_energy(m, t, Q, n, p, eps, barrier)};
        };
        const auto [w0, r0] = parts();
        REQUIRE(std::isfinite(w0));
        CHECK(r0 > 0.0);  // the opposite corners are never in the moving part
        // A sum stopped at a bound: at least the bound and at most the whole;
        // the whole where the bound is above it.
        const double v0 = w0 - r0, full = tspline::layout_moving_energy(m, t, Q, n, p, eps, barrier);
        const double stopped = tspline::layout_moving_energy(m, t, Q, n, p, eps, barrier, 0.5 * full);
        CHECK(stopped >= 0.5 * full);
        CHECK(stopped <= full);
        CHECK(tspline::layout_moving_energy(m, t, Q, n, p, eps, barrier, 1.001 * full) == full);
        CHECK(full == doctest::Approx(v0));
        // Prepared for a search of n where it stands: the same sums, bit for bit, wherever n goes.
        const tspline::LayoutMovingEnergy prepared(m, t, Q, n, p, eps, barrier);
        CHECK(prepared() == full);
        for (const double u : {-0.05, -0.02, 0.03, 0.06}) {
          if (m.ring[n] < 0) {
            m.x[n] = keep.x[n] + V(u, 0.6 * u);
          } else {
            m.arc[n] = std::fmod(keep.arc[n] + u + c.length(), c.length());
            m.x[n] = c.point(m.arc[n]);
          }
          const auto [w, r] = parts();
          if (!std::isfinite(w)) {  // a corner inverted (the barrier), by the move: in the moving part
            CHECK(std::isinf(tspline::layout_moving_energy(m, t, Q, n, p, eps, barrier)));
            continue;
          }
          ++finite_moves;
          const double moved = tspline::layout_moving_energy(m, t, Q, n, p, eps, barrier);
          CHECK(prepared() == moved);
          CHECK(prepared(0.5 * moved) == tspline::layout_moving_energy(m, t, Q, n, p, eps, barrier, 0.5 * moved));
          CHECK(w != doctest::Approx(w0));  // the move changed the energy
          // Equal to round-off in the sums (of terms up to w).
          CHECK(std::abs(r - r0) <= 1e-13 * std::max(w, w0));
        }
        m = keep;
      }
    }
    CHECK(finite_moves >= 50);  // of 72 (57: the rest invert a corner)
  }

  TEST_CASE("node optimization: a displaced centre and a displaced ring node go back to the square grid") {
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, 0), V(1, 1), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    tspline::LayoutMesh m = square_2x2(ring.curves[0], V(0.8, 0.7), 0.3);
    const tspline::LayoutOptimizationReport r = tspline::optimize_layout_nodes(m, Q, anywhere);
    CHECK(r.before.mean_ratio < 0.6);
    CHECK(r.after.mean_ratio > 0.99);
    CHECK(r.after.scaled_jacobian > 0.99);
    CHECK((m.x[8] - V(0.5, 0.5)).norm() < 1e-2);
    CHECK((m.x[1] - V(0.5, 0.0)).norm() < 1e-2);
    CHECK(m.arc[1] == doctest::Approx(0.5).epsilon(2e-2));  // the ring node slid along its ring
    CHECK(m.x[1].y() == 0.0);                               // ... and stayed on it
    // The corners are pinned: a ring node whose quad corner is the ring's corner does not slide.
    CHECK(m.x[0] == V(0, 0));
    CHECK(m.x[2] == V(1, 0));
  }

  TEST_CASE("node optimization: a centre outside its star (inverted corners) is untangled") {
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, 0), V(1, 1), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    // Also where no move may put more patch corners out of range than before
    // it (keep_patch_corners_in_range): the guard counts, it does not pin a
    // node whose corners are out of range already.
    for (const bool keep : {false, true}) {
      CAPTURE(keep);
      tspline::LayoutMesh m = square_2x2(ring.curves[0], V(0.9, 0.1), 0.5);
      const tspline::LayoutTopology t(m);
      CHECK(tspline::worst_layout_quality(m, t, Q).scaled_jacobian < 0.0);  // a reflex corner at (0.5, 0)
      tspline::LayoutOptimizationOptions o;
      o.keep_patch_corners_in_range = keep;
      const tspline::LayoutOptimizationReport r = tspline::optimize_layout_nodes(m, Q, anywhere, {}, o);
      CHECK(r.before.scaled_jacobian < 0.0);
      CHECK(r.after.scaled_jacobian > 0.99);
    }
  }

  TEST_CASE(
      "node optimization: while the layout is tangled only a ring node with an inverted corner slides") {
    // The 2 x 2 square with a notch in its bottom coast, the bottom ring node
    // at the notch's tip (0.5, -0.3) and the centre to its upper right: the
    // node's corner towards the notch's right flank is inverted. While the
    // layout is tangled, ring nodes stay where they are, except such a node
    // (untangle_ring_corners); the right ring node (1, 0.5), whose corners are
    // fine, stays either way.
    const tspline::LayoutRings ring =
        one_ring({V(0, 0), V(0.4, 0), V(0.5, -0.3), V(0.6, 0), V(1, 0), V(1, 1), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    const tspline::RingCurve& c = ring.curves[0];
    const double tip = 0.4 + std::hypot(0.1, 0.3);
    auto start = [&] {
      tspline::LayoutMesh m = square_2x2(c, V(0.8, 0.3), 0.5);
      m.arc[1] = tip;
      m.x[1] = c.point(tip);
      return m;
    };
    auto inverted_at = [&](const tspline::LayoutMesh& m, int n) {
      const tspline::LayoutTopology t(m);
      bool inverted = false;
      for (const auto& [q, j] : t.corners_of(n))
        inverted = inverted || Q.corner(m, t, q, j).scaled_jacobian <= 0.0;
      return inverted;
    };
    {
      const tspline::LayoutMesh m = start();
      REQUIRE((m.x[1] - V(0.5, -0.3)).norm() < 1e-12);
      REQUIRE(inverted_at(m, 1));
      REQUIRE(!inverted_at(m, 3));
    }
    for (const bool on : {false, true}) {
      CAPTURE(on);
      tspline::LayoutOptimizationOptions o;
      o.untangle_ring_corners = on;
      o.max_sweeps = 1;  // a tangled sweep
      tspline::LayoutMesh m = start();
      const tspline::LayoutOptimizationReport r = tspline::optimize_layout_nodes(m, Q, anywhere, {}, o);
      CHECK(r.before.scaled_jacobian < 0.0);
      CHECK((m.x[1] != V(0.5, -0.3)) == on);
      CHECK((m.x[1] - c.point(m.arc[1])).norm() < 1e-12);  // slid along its ring
      CHECK(m.x[3] == V(1, 0.5));
      // In full: untangled.
      o.max_sweeps = 60;
      m = start();
      CHECK(tspline::optimize_layout_nodes(m, Q, anywhere, {}, o).after.scaled_jacobian > 0.0);
    }
  }

  TEST_CASE("node optimization: an untangled layout stays untangled, even to relieve a pinched side") {
    // The 2 x 2 square whose bottom coast rises in a spike at x = 0.25 to height
    // h, through the top of the lower-left quad: its bottom side is pinched
    // (side shape <= 0) wherever the nodes go short of a fold. The quality
    // sweeps may not buy the pinch off with a folded corner (a corner's
    // regularized energy at a fold is finite: the quality phase needs a barrier).
    for (const double h : {0.6, 0.8, 0.95}) {
      CAPTURE(h);
      const tspline::LayoutRings ring =
          one_ring({V(0, 0), V(0.24, 0), V(0.25, h), V(0.26, 0), V(1, 0), V(1, 1), V(0, 1)});
      const tspline::LayoutQuality Q(ring);
      tspline::LayoutMesh m = square_2x2(ring.curves[0], V(0.5, 0.5), 0.5);
      const tspline::LayoutTopology t(m);
      REQUIRE(tspline::worst_layout_quality(m, t, Q).scaled_jacobian > 0.0);
      REQUIRE(Q.side_shape(m, t, 0, 0) <= 0.0);
      const tspline::LayoutOptimizationReport r = tspline::optimize_layout_nodes(m, Q, anywhere);
      CHECK(r.before.scaled_jacobian > 0.0);
      for (std::size_t q = 0; q < m.quads.size(); ++q)
        for (int j = 0; j < 4; ++j) CHECK(Q.corner(m, t, static_cast<int>(q), j).scaled_jacobian > 0.0);
      CHECK(r.after.scaled_jacobian > 0.0);
    }
  }

  TEST_CASE("node optimization and edge rotations stop with LayoutCancelled once the cancel flag is set") {
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, 0), V(1, 1), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    tspline::LayoutMesh m = square_2x2(ring.curves[0], V(0.8, 0.7), 0.5);
    const tspline::LayoutMesh before = m;
    std::atomic<bool> cancel{true};
    tspline::LayoutOptimizationOptions o;
    o.cancel = &cancel;
    CHECK_THROWS_AS(tspline::optimize_layout_nodes(m, Q, anywhere, {}, o), tspline::LayoutCancelled);
    CHECK(m.x == before.x);  // stopped before its first sweep
    tspline::LayoutRotationOptions r;
    r.cancel = &cancel;
    r.target = 2.0;  // every quad is "poor": a batch is due
    CHECK_THROWS_AS(tspline::rotate_layout_edges(m, Q, anywhere, r), tspline::LayoutCancelled);
    cancel = false;
    CHECK(tspline::optimize_layout_nodes(m, Q, anywhere, {}, o).after.scaled_jacobian > 0.99);
  }

  TEST_CASE("node optimization keeps nodes where the caller's check refuses the move") {
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, 0), V(1, 1), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    tspline::LayoutMesh m = square_2x2(ring.curves[0], V(0.8, 0.7), 0.5);
    // The centre may not go left of x = 0.75: it ends on that line, as high as is best.
    const tspline::LayoutAdmissible right = [](const tspline::LayoutMesh& mm, const tspline::LayoutTopology&, int n) {
      return mm.ring[n] >= 0 || mm.x[n].x() >= 0.75;
    };
    tspline::optimize_layout_nodes(m, Q, right);
    CHECK(m.x[8].x() >= 0.75);
    CHECK(m.x[8].x() < 0.76);
  }

  TEST_CASE("edge rotations tried in batches on threads give the layout that one-by-one tries give") {
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, 0), V(1, 1), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    const tspline::LayoutMesh start = sheared_grid(ring);
    tspline::LayoutRotationOptions one_by_one, batched;
    one_by_one.max_batch = 1;
    one_by_one.target = batched.target = 0.8;
    tspline::LayoutMesh a = start, b = start;
    const tspline::LayoutRotationReport ra = tspline::rotate_layout_edges(a, Q, anywhere, one_by_one);
    const tspline::LayoutRotationReport rb = tspline::rotate_layout_edges(b, Q, anywhere, batched);
    CHECK(ra.tried > 20);
    CHECK(ra.kept > 0);
    CHECK(rb.tried == ra.tried);
    CHECK(rb.kept == ra.kept);
    CHECK(a.quads == b.quads);
    CHECK(a.x == b.x);
    CHECK(a.arc == b.arc);
    // Tries that found nothing are made again in later rounds only where a
    // node they read has moved: trying every one again gives the same layout.
    tspline::LayoutRotationOptions every_try = one_by_one;
    every_try.skip_known_failures = false;
    tspline::LayoutMesh c = start;
    const tspline::LayoutRotationReport rc = tspline::rotate_layout_edges(c, Q, anywhere, every_try);
    MESSAGE("tries: every one " << rc.tried << ", skipping known failures " << ra.tried);
    CHECK(rc.tried > ra.tried);
    CHECK(rc.kept == ra.kept);
    CHECK(a.quads == c.quads);
    CHECK(a.x == c.x);
    CHECK(a.arc == c.arc);
  }

  TEST_CASE("node optimization in batches on threads gives the layout that moving nodes one by one gives") {
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(1, 0), V(1, 1), V(0, 1)});
    const tspline::LayoutQuality Q(ring);
    const tspline::LayoutMesh start = sheared_grid(ring);
    tspline::LayoutOptimizationOptions one_by_one, batched;
    one_by_one.in_batches = false;
    // With moves refused, as the true geometry's check refuses some: no node
    // may enter the band 0.45 < x < 0.55 (those in it may leave).
    const tspline::LayoutAdmissible outside_band = [](const tspline::LayoutMesh& m,
                                                      const tspline::LayoutTopology&,
                                                      int n) { return std::abs(m.x[n].x() - 0.5) >= 0.05; };
    for (const auto& admissible : {anywhere, outside_band}) {
      tspline::LayoutMesh a = start, b = start;
      const tspline::LayoutOptimizationReport ra =
          tspline::optimize_layout_nodes(a, Q, admissible, {}, one_by_one);
      const tspline::LayoutOptimizationReport rb =
          tspline::optimize_layout_nodes(b, Q, admissible, {}, batched);
      MESSAGE("worst J_r " << ra.before.mean_ratio << " -> " << ra.after.mean_ratio << " in " << ra.sweeps
                           << " sweeps, " << ra.moves << " moves");
      CHECK(ra.moves > 500);
      CHECK(ra.after.mean_ratio > ra.before.mean_ratio + 0.5);
      CHECK(rb.sweeps == ra.sweeps);
      CHECK(rb.moves == ra.moves);
      CHECK(a.x == b.x);
      CHECK(a.arc == b.arc);
    }
  }

  TEST_CASE("edge rotation: a long hexagon split by its long diagonal is split by a short one instead") {
    // h0 .. h5 counter-clockwise; two quads share h0-h3 (length 6): corners of 26.6
    // degrees between sides of ratio 6 / sqrt 5 at h0 and h3.
    const std::vector<V> h = {V(-3, 0), V(-1, -1), V(1, -1), V(3, 0), V(1, 1), V(-1, 1)};
    const tspline::LayoutRings ring = one_ring(h);
    const tspline::LayoutQuality Q(ring);
    tspline::LayoutMesh m = ring_mesh(ring.curves[0], h, {}, {{0, 1, 2, 3}, {3, 4, 5, 0}});
    const double before = std::min(tspline::layout_quad_figure(m, tspline::LayoutTopology(m), Q, 0),
                                   tspline::layout_quad_figure(m, tspline::LayoutTopology(m), Q, 1));
    CHECK(before == doctest::Approx(2.0 * std::sin(std::atan(0.5)) * std::sqrt(5.0) * 6.0 / 41.0));
    const tspline::LayoutRotationReport r = tspline::rotate_layout_edges(m, Q, anywhere);
    CHECK(r.kept >= 1);
    const tspline::LayoutTopology t(m);
    double after = 1.0;
    for (int q = 0; q < 2; ++q) after = std::min(after, tspline::layout_quad_figure(m, t, Q, q));
    CHECK(after > before + 0.1);
    // Still two counter-clockwise quads, sharing one edge that is not h0-h3.
    REQUIRE(m.quads.size() == 2);
    int shared = 0;
    for (int j = 0; j < 4; ++j)
      if (!t.on_ring(0, j)) {
        ++shared;
        const int a = m.quads[0][j], b = m.quads[0][(j + 1) % 4];
        CHECK_FALSE(((a == 0 && b == 3) || (a == 3 && b == 0)));
      }
    CHECK(shared == 1);
    for (const auto& q : m.quads) CHECK(quad_area(m, q) > 0.0);
  }

  TEST_CASE("opening: a crack tip split into two 169-degree corners gets a third quad, no rotation could") {
    // The square [-2, 2]^2 with a notch from the top down to its tip N = (0, 0)
    // between F = (0.4, 2) and G = (-0.4, 2): domain angle at N 360 - 2 atan(0.2)
    // = 337.4 degrees, split by the mesh into two corners of 168.7. The inner
    // node c below N has valence 4, its other neighbours X and Y valence 3, so
    // no edge rotation gives N a third quad (each would leave X or Y with 2).
    const std::vector<V> ring_points = {V(-2, -2), V(0, -2), V(2, -2), V(2, 2),
                                        V(0.4, 2), V(0, 0),  V(-0.4, 2), V(-2, 2)};
    const tspline::LayoutRings ring = one_ring(ring_points);
    const tspline::LayoutQuality Q(ring);
    enum { A, B, C, E, F, N, G, H, c, X, Y };
    tspline::LayoutMesh m = ring_mesh(ring.curves[0], ring_points, {V(0, -1), V(1.0, 0.2), V(-1.0, 0.2)},
                                      {{N, c, X, F}, {N, G, Y, c}, {c, B, C, X}, {X, C, E, F}, {Y, A, B, c}, {G, H, A, Y}});
    auto degrees_at = [&](const tspline::LayoutMesh& mesh, int node) {
      const tspline::LayoutTopology t(mesh);
      std::vector<double> d;
      for (const auto& [q, j] : t.corners_of(node)) {
        const auto [a, b] = Q.corner_vectors(mesh, t, q, j, 0.0);
        double deg = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)) * 180.0 / std::numbers::pi;
        d.push_back(deg < 0.0 ? deg + 360.0 : deg);
      }
      return d;
    };
    const double tip = 360.0 - 2.0 * std::atan(0.2) * 180.0 / std::numbers::pi;
    const std::vector<double> before = degrees_at(m, N);
    REQUIRE(before.size() == 2);
    CHECK(before[0] + before[1] == doctest::Approx(tip));
    CHECK(*std::max_element(before.begin(), before.end()) > 160.0);
    // No rotation is possible (and none kept).
    tspline::LayoutMesh rotated = m;
    CHECK(tspline::rotate_layout_edges(rotated, Q, anywhere).kept == 0);

    const tspline::LayoutOpeningReport r = tspline::open_wide_ring_corners(m, Q, anywhere);
    CHECK(r.kept == 1);
    REQUIRE(m.size() == 12);
    REQUIRE(m.quads.size() == 7);
    const std::vector<double> after = degrees_at(m, N);
    REQUIRE(after.size() == 3);
    double sum = 0.0;
    for (const double d : after) {
      sum += d;
      CHECK(d < 150.0);
      CHECK(d > 60.0);
    }
    CHECK(sum == doctest::Approx(tip));
    // Still a quad mesh of the domain: counter-clockwise quads, each edge on
    // the ring or shared by two quads, the ring's 8 pieces each covered once,
    // Euler's count for a disk (quads = inner nodes + ring nodes / 2 - 1),
    // inner nodes of valence >= 3.
    const tspline::LayoutTopology t(m);
    for (const auto& q : m.quads) CHECK(quad_area(m, q) > 0.0);
    int on_ring = 0, inner = 0;
    for (int q = 0; q < static_cast<int>(m.quads.size()); ++q)
      for (int j = 0; j < 4; ++j) {
        on_ring += t.on_ring(q, j) ? 1 : 0;
        CHECK((t.on_ring(q, j) || t.across(q, j).first >= 0));
      }
    CHECK(on_ring == 8);
    for (int n = 0; n < static_cast<int>(m.size()); ++n)
      if (m.ring[n] < 0) {
        ++inner;
        CHECK(t.valence(n) >= 3);
      }
    CHECK(static_cast<int>(m.quads.size()) == inner + 8 / 2 - 1);
    // Nothing wide is left: a second pass keeps nothing.
    CHECK(tspline::open_wide_ring_corners(m, Q, anywhere).kept == 0);
  }

  TEST_CASE("openings tried in batches on threads give the layout that one-by-one tries give") {
    // A comb: blocks [4k - 2, 4k + 2] x [-2, 2] side by side; blocks 0, 4 and
    // 8 each hold the crack tip of the test above (a notch from the top down
    // to (4k, 0)), the others are two quads. The tips are far enough apart
    // for their tries to share a batch.
    const int K = 9;
    auto notch = [](int k) { return k % 4 == 0; };
    std::vector<V> ring_points;
    std::vector<int> A(K + 1), B(K), H(K + 1), F(K), N(K), G(K), Z(K);
    for (int k = 0; k < K; ++k) {
      A[k] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * k - 2, -2));
      B[k] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * k, -2));
    }
    A[K] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * K - 2, -2));
    H[K] = static_cast<int>(ring_points.size()),
    ring_points.push_back(V(4 * K - 2, 2));  // the top right corner
    for (int k = K - 1; k >= 0; --k) {
      if (notch(k)) {
        F[k] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * k + 0.4, 2));
        N[k] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * k, 0));
        G[k] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * k - 0.4, 2));
      } else {
        Z[k] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * k, 2));
      }
      H[k] = static_cast<int>(ring_points.size()), ring_points.push_back(V(4 * k - 2, 2));
    }
    const int R = static_cast<int>(ring_points.size());
    std::vector<V> inner;
    std::vector<std::array<int, 4>> quads;
    for (int k = 0; k < K; ++k) {
      // Block k: bottom A[k], B[k], A[k + 1]; top H[k + 1] (right), H[k] (left).
      const int a = A[k], b = B[k], c_ = A[k + 1], e = H[k + 1], h = H[k];
      if (!notch(k)) {
        quads.push_back({a, b, Z[k], h});
        quads.push_back({b, c_, e, Z[k]});
        continue;
      }
      const int c = R + static_cast<int>(inner.size()), x = c + 1, y = c + 2;
      inner.push_back(V(4 * k, -1)), inner.push_back(V(4 * k + 1.0, 0.2)),
          inner.push_back(V(4 * k - 1.0, 0.2));
      for (const std::array<int, 4>& q : std::vector<std::array<int, 4>>{{N[k], c, x, F[k]},
                                                                         {N[k], G[k], y, c},
                                                                         {c, b, c_, x},
                                                                         {x, c_, e, F[k]},
                                                                         {y, a, b, c},
                                                                         {G[k], h, a, y}})
        quads.push_back(q);
    }
    const tspline::LayoutRings ring = one_ring(ring_points);
    const tspline::LayoutQuality Q(ring);
    const tspline::LayoutMesh start = ring_mesh(ring.curves[0], ring_points, inner, quads);
    for (const auto& q : start.quads) REQUIRE(quad_area(start, q) > 0.0);
    tspline::LayoutOpeningOptions one_by_one, batched;
    one_by_one.max_batch = 1;
    tspline::LayoutMesh a = start, b = start;
    const tspline::LayoutOpeningReport ra = tspline::open_wide_ring_corners(a, Q, anywhere, one_by_one);
    const tspline::LayoutOpeningReport rb = tspline::open_wide_ring_corners(b, Q, anywhere, batched);
    CHECK(ra.kept == 3);
    CHECK(rb.kept == ra.kept);
    CHECK(rb.tried == ra.tried);
    CHECK(rb.moved == ra.moved);
    CHECK(a.quads == b.quads);
    CHECK(a.x == b.x);
    CHECK(a.arc == b.arc);
  }

  TEST_CASE("a flat single-quad corner marks its ring, and the pillow layer gives it two quads") {
    // A right triangle as one quad whose fourth corner is the hypotenuse's midpoint (180 degrees).
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(2, 0), V(0, 2)});
    const tspline::LayoutQuality Q(ring);
    tspline::LayoutMesh m = ring_mesh(ring.curves[0], {V(0, 0), V(2, 0), V(1, 1), V(0, 2)}, {}, {{0, 1, 2, 3}});
    const std::vector<char> flat = tspline::rings_with_flat_corners(m, Q);
    REQUIRE(flat.size() == 1);
    CHECK(flat[0] == 1);
    CHECK(tspline::pillow_rings(m, flat) == 1);
    // 1 quad and 4 layer quads; the right angle at (0, 0), the first convex corner of the
    // old quad, keeps one quad (its hexagon re-split: one quad less, its moved node unused).
    CHECK(m.quads.size() == 4);
    CHECK(m.size() == 8);
    const tspline::LayoutTopology t(m);
    int on_ring = 0, unused = 0;
    for (std::size_t n = 0; n < m.size(); ++n) {
      const std::size_t k = t.valence(static_cast<int>(n));
      if (k == 0) ++unused;
      if (m.ring[n] < 0) continue;
      ++on_ring;
      if (m.x[n] == V(1, 1)) CHECK(k == 2);  // the flat corner: two quads of about 90 degrees
      if (m.x[n] == V(0, 0)) CHECK(k == 1);  // the corner kept whole
    }
    CHECK(on_ring == 4);
    CHECK(unused == 1);
    // The signed areas of the quads add up to the triangle's, 2: the boundary is kept.
    double area = 0.0;
    for (const auto& q : m.quads) area += quad_area(m, q);
    CHECK(area == doctest::Approx(2.0));
    CHECK(tspline::rings_with_flat_corners(m, Q)[0] == 0);
  }

  TEST_CASE("a sheet of quads through a flat single-quad corner gives it two quads and ends on the ring") {
    // The right triangle of the pillow test: one quad, its corner at (1, 1) flat.
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(2, 0), V(0, 2)});
    const tspline::LayoutQuality Q(ring);
    tspline::LayoutMesh m = ring_mesh(ring.curves[0], {V(0, 0), V(2, 0), V(1, 1), V(0, 2)}, {}, {{0, 1, 2, 3}});
    const std::vector<int> flat = tspline::flat_ring_corners(m, Q);
    REQUIRE(flat == std::vector<int>{2});
    // Too few quads allowed: nothing changes.
    const tspline::LayoutMesh before = m;
    CHECK(tspline::insert_corner_sheets(m, ring, flat, 1) == 0);
    CHECK(m.quads == before.quads);
    CHECK(m.x == before.x);
    // The quad cut in three; both ends of the sheet are ring edges, halved by new ring nodes.
    CHECK(tspline::insert_corner_sheets(m, ring, flat, 100) == 2);
    REQUIRE(m.quads.size() == 3);
    REQUIRE(m.size() == 7);
    const tspline::LayoutTopology t(m);
    CHECK(t.valence(2) == 2);
    int on_ring = 0;
    for (std::size_t n = 0; n < m.size(); ++n) {
      if (m.ring[n] < 0) continue;
      ++on_ring;
      // A ring node lies where its arc length says.
      CHECK((ring.curves[0].point(m.arc[n]) - m.x[n]).norm() < 1e-14);
    }
    CHECK(on_ring == 6);  // (1, 0) and (0, 1), the midpoints of the two legs, are ring nodes now
    CHECK(std::count(m.x.begin(), m.x.end(), V(1, 0)) == 1);
    CHECK(std::count(m.x.begin(), m.x.end(), V(0, 1)) == 1);
    double area = 0.0;
    for (const auto& q : m.quads) {
      const double a = quad_area(m, q);
      CHECK(a > 0.0);
      area += a;
    }
    CHECK(area == doctest::Approx(2.0));
    CHECK(tspline::flat_ring_corners(m, Q).empty());
  }

  TEST_CASE("a sheet that crosses itself cuts that quad in four and keeps the mesh conforming") {
    // The triangle (0, 0), (4, 0), (0, 4): a quad at the flat corner (2, 2) of the
    // hypotenuse and the quad (0, 0), (4, 0), (1, 1), (0, 4) beside it, which the
    // sheet leaving the first quad by both of its inner edges crosses twice.
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(4, 0), V(0, 4)});
    const tspline::LayoutQuality Q(ring);
    tspline::LayoutMesh m = ring_mesh(ring.curves[0], {V(0, 0), V(4, 0), V(2, 2), V(0, 4)}, {V(1, 1)},
                                      {{2, 3, 4, 1}, {0, 1, 4, 3}});
    REQUIRE(tspline::flat_ring_corners(m, Q) == std::vector<int>{2});
    CHECK(tspline::insert_corner_sheets(m, ring, {2}, 100) == 5);  // 3 from the corner's quad, 4 from the other
    REQUIRE(m.quads.size() == 7);
    const tspline::LayoutTopology t(m);
    int ring_edges = 0;
    for (int q = 0; q < static_cast<int>(m.quads.size()); ++q)
      for (int j = 0; j < 4; ++j) {
        ring_edges += t.on_ring(q, j) ? 1 : 0;
        CHECK((t.on_ring(q, j) || t.across(q, j).first >= 0));
      }
    CHECK(ring_edges == 6);  // the two legs halved: (2, 0) and (0, 2) are ring nodes
    CHECK(t.valence(2) == 2);
    double area = 0.0;
    for (const auto& q : m.quads) area += quad_area(m, q);
    CHECK(area == doctest::Approx(8.0));
    CHECK(tspline::flat_ring_corners(m, Q).empty());
  }

  TEST_CASE("a sheet that comes back into its corner's quad is closed: it cuts the loop of quads around a hole") {
    // The square (0, 0)-(4, 4) with the triangular hole (2, 1), (3, 3), (1, 3): four
    // quads around the hole, the bottom one with the flat corner (2, 0) on the
    // outer ring. The sheet leaving it through X-a runs around the hole and comes
    // back through b-X: no ring is reached, no ring node is made.
    tspline::LayoutRings R;
    R.curves.emplace_back(std::vector<V>{V(0, 0), V(4, 0), V(4, 4), V(0, 4)});
    R.curves.emplace_back(std::vector<V>{V(2, 1), V(3, 3), V(1, 3)});
    const tspline::LayoutQuality Q(R);
    tspline::LayoutMesh m = ring_mesh(R.curves[0], {V(0, 0), V(2, 0), V(4, 0), V(4, 4), V(0, 4)}, {},
                                      {{1, 2, 5, 0}, {2, 3, 6, 5}, {3, 4, 7, 6}, {4, 0, 5, 7}});
    for (std::size_t i = 0; i < 3; ++i) {  // nodes 5, 6, 7: the hole's vertices
      m.x.push_back(R.curves[1].vertex(i));
      m.ring.push_back(1);
      m.arc.push_back(R.curves[1].arc(i));
    }
    REQUIRE(tspline::flat_ring_corners(m, Q) == std::vector<int>{1});
    // 2 quads more from the corner's quad, one from each of the other three.
    CHECK(tspline::insert_corner_sheets(m, R, {1}, 100) == 5);
    REQUIRE(m.quads.size() == 9);
    CHECK(m.size() == 13);  // v', the midpoints of X-a and b-X and of the two other radial edges
    CHECK(std::count_if(m.ring.begin(), m.ring.end(), [](int r) { return r >= 0; }) == 8);
    const tspline::LayoutTopology t(m);
    CHECK(t.valence(1) == 2);
    int ring_edges = 0;
    double area = 0.0;
    for (int q = 0; q < static_cast<int>(m.quads.size()); ++q) {
      for (int j = 0; j < 4; ++j) {
        ring_edges += t.on_ring(q, j) ? 1 : 0;
        CHECK((t.on_ring(q, j) || t.across(q, j).first >= 0));  // conforming
      }
      const double a = quad_area(m, m.quads[q]);
      CHECK(a > 0.0);
      area += a;
    }
    CHECK(ring_edges == 8);  // 5 outer ring pieces, 3 of the hole
    CHECK(area == doctest::Approx(14.0));  // 16 less the hole's 2
    CHECK(tspline::flat_ring_corners(m, Q).empty());
  }

  TEST_CASE("pillowing keeps convex corners whole: a 3 x 3 grid's corners stay single-quad corners") {
    const tspline::LayoutRings ring = one_ring({V(0, 0), V(3, 0), V(3, 3), V(0, 3)});
    // Ring nodes counter-clockwise from (0, 0), then the inner nodes (1, 1), (2, 1), (2, 2), (1, 2).
    const std::vector<V> on_ring = {V(0, 0), V(1, 0), V(2, 0), V(3, 0), V(3, 1), V(3, 2),
                                    V(3, 3), V(2, 3), V(1, 3), V(0, 3), V(0, 2), V(0, 1)};
    tspline::LayoutMesh m = ring_mesh(ring.curves[0], on_ring, {V(1, 1), V(2, 1), V(2, 2), V(1, 2)},
                                      {{0, 1, 12, 11}, {1, 2, 13, 12}, {2, 3, 4, 13},
                                       {12, 13, 14, 15}, {13, 4, 5, 14}, {11, 12, 15, 10},
                                       {10, 15, 9, 9}, {15, 14, 7, 8}, {14, 5, 6, 7}});
    m.quads[6] = {10, 15, 8, 9};  // the top-left quad
    REQUIRE(tspline::pillow_rings(m, {1}) == 1);
    // 9 quads, 12 layer quads, less one for each of the 4 corners.
    CHECK(m.quads.size() == 9 + 12 - 4);
    const tspline::LayoutTopology t(m);
    int corners = 0, unused = 0, threes = 0;
    double area = 0.0;
    for (std::size_t n = 0; n < m.size(); ++n) {
      const int k = static_cast<int>(t.valence(static_cast<int>(n)));
      if (k == 0) ++unused;
      if (m.ring[n] < 0 || k == 0) continue;
      const bool corner = (m.x[n].x() == 0.0 || m.x[n].x() == 3.0) && (m.x[n].y() == 0.0 || m.x[n].y() == 3.0);
      // A corner keeps one quad; per corner one ring neighbour gets the cut of the
      // re-split hexagon (3 quads), every other ring node has 2.
      if (corner) CHECK(k == 1);
      else CHECK((k == 2 || k == 3));
      corners += corner;
      threes += k == 3;
    }
    CHECK(corners == 4);
    CHECK(threes == 4);
    CHECK(unused == 4);  // the moved corner nodes
    for (const auto& q : m.quads) {
      const double a = quad_area(m, q);
      CHECK(a > 0.0);
      area += a;
    }
    CHECK(area == doctest::Approx(9.0));
  }

  TEST_CASE("ring geometry on its grid: inside and the first edge crossed, as by every edge in turn") {
    // A star of 60 spikes (edges across many grid cells) and a hole: points and
    // segments all over, against the even-odd rule and the lowest-numbered
    // crossed edge found by testing every edge.
    std::vector<V> star;
    for (int k = 0; k < 120; ++k) {
      const double a = 2.0 * std::numbers::pi * k / 120.0, r = k % 2 ? 0.35 : 1.0;
      star.push_back(V(r * std::cos(a), r * std::sin(a)));
    }
    const std::vector<tspline::RingCurve> rings = {
        tspline::RingCurve(star), tspline::RingCurve({V(-0.1, -0.1), V(-0.1, 0.1), V(0.1, 0.1), V(0.1, -0.1)})};
    const tspline::RingGeometry g = tspline::RingGeometry::of_rings(rings);
    auto brute_inside = [&](const V& p) {
      bool in = false;
      for (std::size_t e = 0; e < g.size(); ++e) {
        const V &a = g.edge(static_cast<int>(e)).a, &b = g.edge(static_cast<int>(e)).b;
        if ((a.y() > p.y()) != (b.y() > p.y()) && a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x()) > p.x())
          in = !in;
      }
      return in;
    };
    std::uint64_t state = 12345;
    auto uniform = [&] {  // in [-1.1, 1.1)
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      return -1.1 + 2.2 * static_cast<double>(state >> 11) / 9007199254740992.0;
    };
    int inside = 0, crossed = 0;
    for (int k = 0; k < 2000; ++k) {
      const V p(uniform(), uniform()), q = p + 0.15 * V(uniform(), uniform());
      CAPTURE(p);
      CHECK(g.inside(p) == brute_inside(p));
      inside += g.inside(p);
      int first = -1;
      for (std::size_t e = 0; e < g.size() && first < 0; ++e) {
        const auto& f = g.edge(static_cast<int>(e));
        if (tspline::segments_intersect(p, q, f.a, f.b)) first = static_cast<int>(e);
      }
      CHECK(g.crossing(p, q, false, false, 1e-9) == first);
      crossed += first >= 0;
    }
    CHECK(inside > 200);  // both answers are common
    CHECK(inside < 1800);
    CHECK(crossed > 200);
    CHECK(crossed < 1800);
  }

  TEST_CASE("layout cut checks agree with the patch layout's on every chord between ring points") {
    // A stepped outer ring (cuts can go on along an edge's line, or leave the
    // domain through the notch touching the ring only at their ends) with a
    // hole; the ring points are the vertices and the edge midpoints. Every
    // chord between two of them: the layout's test (admits_cut: no crossing,
    // midpoint inside) says yes exactly where the patch layout's validate_cuts
    // takes the chord as a cut; crossings alone miss the chords outside.
    tspline::Domain d;
    d.outer = test_support::make_polygon({{0, 0}, {4, 0}, {4, 2}, {2, 2}, {2, 4}, {0, 4}});
    d.holes = {test_support::make_polygon({{0.5, 0.5}, {1.5, 0.5}, {1.5, 1.5}, {0.5, 1.5}})};
    d = tspline::validate_domain(d);
    std::vector<tspline::RingCurve> rings = {tspline::RingCurve(d.outer.vertices)};
    for (const auto& h : d.holes) rings.emplace_back(h.vertices);
    const tspline::RingGeometry g = tspline::RingGeometry::of_rings(rings);
    std::vector<V> points;
    for (const auto& r : rings)
      for (std::size_t i = 0; i < r.size(); ++i) {
        points.push_back(r.vertex(i));
        points.push_back(0.5 * (r.vertex(i) + r.vertex(i + 1)));
      }
    const double tol = 1e-9 * 4.0 * std::sqrt(2.0);
    int accepted = 0, refused = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
      for (std::size_t j = i + 1; j < points.size(); ++j) {
        const V a = points[i], b = points[j];
        CAPTURE(a);
        CAPTURE(b);
        const bool layout_ok = g.admits_cut(a, b, true, true, tol);
        bool patch_ok = true;
        try {
          tspline::validate_cuts(d, {{a, b}});
        } catch (const tspline::InputError&) {
          patch_ok = false;
        }
        CHECK(layout_ok == patch_ok);
        (patch_ok ? accepted : refused) += 1;
      }
    CHECK(accepted > 50);
    CHECK(refused > 50);
    CHECK_FALSE(g.crosses(V(4, 2), V(2, 4), true, true, tol));  // through the notch, outside
    CHECK_FALSE(g.admits_cut(V(4, 2), V(2, 4), true, true, tol));
  }

  TEST_CASE("ring geometry: inside a square with a hole, segments crossing a ring, the nearest edge") {
    const std::vector<tspline::RingCurve> rings = {
        tspline::RingCurve({V(0, 0), V(4, 0), V(4, 4), V(0, 4)}),
        tspline::RingCurve({V(1, 1), V(2, 1), V(2, 2), V(1, 2)})};
    const tspline::RingGeometry g = tspline::RingGeometry::of_rings(rings);
    CHECK(g.size() == 8);
    CHECK(g.inside(V(3, 3)));
    CHECK_FALSE(g.inside(V(1.5, 1.5)));  // in the hole
    CHECK_FALSE(g.inside(V(5, 1)));
    CHECK(g.crosses(V(0.5, 1.5), V(3, 1.5), false, false, 1e-9));        // through the hole
    CHECK_FALSE(g.crosses(V(0.5, 3), V(3, 3), false, false, 1e-9));      // above it
    CHECK_FALSE(g.crosses(V(0, 3), V(1, 1.5), true, true, 1e-9));        // from ring to ring
    // A cut that ends on a ring vertex and goes on along an edge's line there
    // makes a flat patch corner: a crossing, as the patch layout has it; one
    // that leaves the vertex at an angle does not cross.
    CHECK(g.crosses(V(1, 1), V(0.5, 1), true, false, 1e-9));
    CHECK(g.crosses(V(0.5, 1), V(1, 1), false, true, 1e-9));
    CHECK_FALSE(g.crosses(V(1, 1), V(0.5, 0.5), true, false, 1e-9));
    CHECK_FALSE(g.crosses(V(1, 1), V(0.5, 1.000001), true, false, 1e-9));
    tspline::Domain d;
    d.outer = test_support::make_polygon({{0, 0}, {4, 0}, {4, 4}, {0, 4}});
    d.holes = {test_support::make_polygon({{1, 1}, {2, 1}, {2, 2}, {1, 2}})};
    d = tspline::validate_domain(d);
    CHECK_THROWS_AS(tspline::validate_cuts(d, {{V(1, 1), V(0, 1)}}), tspline::InputError);
    CHECK_NOTHROW(tspline::validate_cuts(d, {{V(1, 1), V(0, 0)}}));
    const int e = g.nearest(V(2.2, 1.5));
    CHECK(g.edge(e).ring == 1);
    CHECK(g.edge(e).a.x() == 2.0);
    CHECK(g.edge(e).b.x() == 2.0);
  }
}
