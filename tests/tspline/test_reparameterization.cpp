// A moved boundary re-parameterized from the previous map (deform/): the
// affine part of the motion is exact, no motion returns the same map, a rigid
// motion the moved map, and a motion that folds the warm start ends untangled
// and certified on the same T-mesh; mismatched boundaries are input errors.
#include <doctest/doctest.h>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "test_support.h"
#include "tspline/deform/boundary_deformation.h"
#include "tspline/deform/layout_reparameterization.h"
#include "tspline/io/gis_reader.h"
#include "tspline/deform/reparameterization.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/errors.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"

namespace {

using tspline::Polygon;

const tspline::ParameterizationResult& isle_of_man() {
  static const tspline::ParameterizationResult r = tspline::run_parameterization(
      tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/isle_of_man.txt"), {}, {});
  return r;
}

// The old polygon (CCW, as the map stores it) with every vertex moved by f.
template <class F>
Polygon moved_by(const Polygon& p, F f) {
  Polygon q = p;
  for (Eigen::Vector2d& v : q.vertices) v = f(v);
  return q;
}

double diameter(const Polygon& p) {
  Eigen::Vector2d lo = p.vertices.front(), hi = lo;
  for (const Eigen::Vector2d& v : p.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return (hi - lo).norm();
}

bool same_tmesh(const tspline::TMesh& a, const tspline::TMesh& b) {
  if (a.num_cells() != b.num_cells() || a.num_vertices() != b.num_vertices()) return false;
  for (int c = 0; c < static_cast<int>(a.num_cells()); ++c)
    if (a.cell_min(c) != b.cell_min(c) || a.cell_max(c) != b.cell_max(c)) return false;
  return true;
}

tspline::ParameterizationResult reparameterize(const tspline::ParameterizationResult& old, const Polygon& moved) {
  return tspline::reparameterize(*old.map, old.front.boundary.polygon(), old.front.boundary.corners().index, moved,
                                 {}, {});
}

// The plate with a hole (8 patches, automatic cuts), validated, and its map.
struct Plate {
  tspline::Domain domain;
  tspline::MultiPatchResult map;
};
const Plate& plate() {
  static const Plate p = [] {
    const tspline::io::DomainInput in =
        tspline::io::read_domain(std::string(TSPLINE_TEST_DATA_DIR) + "/holes/plate_with_hole.txt");
    const tspline::Domain d = tspline::validate_domain({in.outer, in.holes});
    tspline::MultiPatchResult r = tspline::run_multipatch_parameterization(d, std::nullopt, {}, {});
    return Plate{r.domain, std::move(r)};
  }();
  return p;
}

tspline::PreviousLayout previous_of(const tspline::MultiPatchResult& R) {
  tspline::PreviousLayout old;
  old.domain = R.domain;
  for (std::size_t p = 0; p < R.patches.size(); ++p) {
    old.maps.push_back(&*R.patches[p].map);
    old.polygons.push_back(R.patches[p].front.boundary.polygon());
    old.corners.push_back(R.patches[p].front.boundary.corners().index);
  }
  old.interfaces = R.layout.interfaces;
  old.cuts = R.layout.cuts;
  return old;
}

template <class F>
tspline::Domain moved_domain(const tspline::Domain& d, F f) {
  tspline::Domain m = d;
  for (Eigen::Vector2d& v : m.outer.vertices) v = f(v);
  for (Polygon& h : m.holes)
    for (Eigen::Vector2d& v : h.vertices) v = f(v);
  return m;
}

}  // namespace

TEST_SUITE("reparameterization") {
  TEST_CASE("the affine part of a boundary motion is recovered exactly, the residuals are orthogonal to it") {
    std::vector<Eigen::Vector2d> p = {{0, 0}, {3, 0.5}, {4, 2}, {2.5, 4}, {-0.5, 3}, {1, 1.5}};
    Eigen::Matrix2d A;
    A << 1.2, -0.7, 0.4, 0.9;
    const Eigen::Vector2d b(5.0, -3.0);
    std::vector<Eigen::Vector2d> q;
    for (const auto& x : p) q.push_back(A * x + b);
    tspline::BoundaryDeformation d = tspline::fit_boundary_deformation(p, q);
    CHECK((d.A - A).norm() < 1e-13);
    CHECK((d.b - b).norm() < 1e-13);
    CHECK(d.max_residual() < 1e-13);
    // A motion that is not affine: the least-squares residuals sum to zero and
    // have no linear moment (the normal equations), and the vertices are reproduced.
    q[2] += Eigen::Vector2d(0.3, -0.2), q[4] += Eigen::Vector2d(-0.1, 0.4);
    d = tspline::fit_boundary_deformation(p, q);
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    Eigen::Matrix2d moment = Eigen::Matrix2d::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) {
      sum += d.residual[i];
      moment += d.residual[i] * p[i].transpose();
      CHECK((d.affine(p[i]) + d.residual[i] - q[i]).norm() < 1e-13);
    }
    CHECK(sum.norm() < 1e-13);
    CHECK(moment.norm() < 1e-12);
    CHECK(d.max_residual() > 0.1);
    CHECK_THROWS_AS(tspline::fit_boundary_deformation(p, {q.begin(), q.end() - 1}), tspline::InputError);
  }

  TEST_CASE("the residual's extension equals the residual at the polygon's vertices and corners") {
    const auto& r = isle_of_man();
    const tspline::BoundaryMap& bm = r.front.boundary;
    const Polygon& old = bm.polygon();
    const double D = diameter(old);
    const Polygon moved = moved_by(old, [&](const Eigen::Vector2d& x) {
      return Eigen::Vector2d(x.x() + 0.02 * D * std::sin(x.y() / D * 6.0), x.y() + 0.03 * D * std::cos(x.x() / D * 5.0));
    });
    const tspline::BoundaryDeformation d = tspline::fit_boundary_deformation(old.vertices, moved.vertices);
    REQUIRE(d.max_residual() > 1e-3 * D);
    const Eigen::Vector2d uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; ++k)
      CHECK((tspline::residual_extension(bm, d, uv[k]) - d.residual[bm.corners().index[k]]).norm() < 1e-12 * D);
    // Every vertex of the bottom and right chains at its chord parameter.
    const std::size_t n = old.vertices.size();
    for (const tspline::Side side : {tspline::Side::Bottom, tspline::Side::Right}) {
      const auto& t = bm.chain_params(side);
      for (std::size_t j = 0; j < t.size(); ++j) {
        const Eigen::Vector2d at = side == tspline::Side::Bottom ? Eigen::Vector2d(t[j], 0.0) : Eigen::Vector2d(1.0, t[j]);
        const Eigen::Vector2d want = d.residual[(bm.corners().index[static_cast<int>(side)] + j) % n];
        CHECK((tspline::residual_extension(bm, d, at) - want).norm() < 1e-12 * D);
      }
    }
  }

  TEST_CASE("no motion returns the same map, a rigid motion the moved map, on the same T-mesh") {
    const auto& r = isle_of_man();
    REQUIRE(r.map);
    REQUIRE(r.certified_valid());
    const Polygon& old = r.front.boundary.polygon();
    const double D = diameter(old);
    const auto& P = r.map->control_points();

    const tspline::ParameterizationResult same = reparameterize(r, old);
    REQUIRE(same.map);
    CHECK(same.certified_valid());
    CHECK(same_tmesh(same.map->mesh(), r.map->mesh()));
    double err = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i) err = std::max(err, (same.map->control_points()[i] - P[i]).norm());
    MESSAGE("no motion: largest control point change " << err << " (diameter " << D << ")");
    CHECK(err < 1e-12 * D);

    const double th = 0.7;
    Eigen::Matrix2d R;
    R << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
    const Eigen::Vector2d t(123.0, -45.0);
    const tspline::ParameterizationResult rigid =
        reparameterize(r, moved_by(old, [&](const Eigen::Vector2d& x) { return Eigen::Vector2d(R * x + t); }));
    REQUIRE(rigid.map);
    CHECK(rigid.certified_valid());
    CHECK(same_tmesh(rigid.map->mesh(), r.map->mesh()));
    err = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i)
      err = std::max(err, (rigid.map->control_points()[i] - (R * P[i] + t)).norm());
    MESSAGE("rotation and translation: largest control point error " << err);
    CHECK(err < 1e-11 * D);
    CHECK(rigid.dense_quality.min_mean_ratio == doctest::Approx(r.dense_quality.min_mean_ratio).epsilon(1e-9));
  }

  TEST_CASE("a motion that folds the warm start ends untangled and certified") {
    const auto& r = isle_of_man();
    const Polygon& old = r.front.boundary.polygon();
    const double D = diameter(old);
    Eigen::Vector2d lo = old.vertices.front(), hi = lo;
    for (const Eigen::Vector2d& v : old.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const Eigen::Vector2d c = 0.5 * (lo + hi);
    // Each coordinate shifted by a sine wave of the other one, amplitude 7.5 % of the diameter.
    const Polygon moved = moved_by(old, [&](const Eigen::Vector2d& x) {
      return Eigen::Vector2d(x.x() + 0.075 * D * std::sin(2 * M_PI * (x.y() - c.y()) / D),
                             x.y() + 0.075 * D * std::sin(2 * M_PI * (x.x() - c.x()) / D));
    });
    const tspline::BoundaryDeformation d = tspline::fit_boundary_deformation(old.vertices, moved.vertices);
    const tspline::TSplineMap warm = tspline::warm_start_map(*r.map, r.front.boundary, d);
    const tspline::DenseMapQuality wq = tspline::dense_map_quality(warm);
    MESSAGE("warm start: " << wq.nonpositive_det << " samples with det J <= 0, min J_r " << wq.min_mean_ratio);
    REQUIRE(wq.nonpositive_det > 0);  // the warm start is folded
    const tspline::ParameterizationResult m = reparameterize(r, moved);
    REQUIRE(m.map);
    CHECK(m.certified_valid());
    CHECK(tspline::certify_map(*m.map).certified_valid());
    CHECK(m.dense_quality.nonpositive_det == 0);
    CHECK(m.dense_quality.min_mean_ratio > 0.5 * r.dense_quality.min_mean_ratio);
    // The boundary curve follows the moved polygon: each corner exactly.
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      CHECK((m.map->point(uv[k]) - moved.vertices[r.front.boundary.corners().index[k]]).norm() < 1e-9 * D);
    }
    MESSAGE("moved map: " << m.map->mesh().num_cells() << " cells (before " << r.map->mesh().num_cells()
                          << "), whole-map J_r " << m.dense_quality.min_mean_ratio << " (before "
                          << r.dense_quality.min_mean_ratio << ")");
  }

  TEST_CASE("a boundary that does not match the previous map is an input error naming the problem") {
    const auto& r = isle_of_man();
    const Polygon& old = r.front.boundary.polygon();
    Polygon shorter = old;
    shorter.vertices.pop_back(), shorter.file_index.pop_back();
    CHECK_THROWS_WITH_AS(reparameterize(r, shorter), doctest::Contains("vertices"), tspline::InputError);
    // Two vertices swapped: the ring crosses itself, named by file vertex indices.
    Polygon crossing = old;
    std::swap(crossing.vertices[10], crossing.vertices[30]);
    CHECK_THROWS_WITH_AS(reparameterize(r, crossing), doctest::Contains("not simple"), tspline::InputError);
    // A reflection turns the ring the other way round.
    const Polygon mirrored = moved_by(old, [](const Eigen::Vector2d& x) { return Eigen::Vector2d(-x.x(), x.y()); });
    CHECK_THROWS_WITH_AS(reparameterize(r, mirrored), doctest::Contains("other way round"), tspline::InputError);
    // The file's numbering: a ring read with another vertex count.
    Polygon read;
    for (int i = 0; i < 10; ++i) read.vertices.push_back({std::cos(i * 0.6), std::sin(i * 0.6)});
    CHECK_THROWS_WITH_AS(tspline::corresponding_polygon(old, read, "the outer ring"),
                         doctest::Contains("the outer ring of the moved boundary has 10 vertices"),
                         tspline::InputError);
  }

  TEST_CASE("a multi-patch map: no motion, a rigid motion, a smooth motion; interfaces stay conforming") {
    const Plate& P = plate();
    REQUIRE(P.map.certified_valid());
    const tspline::PreviousLayout old = previous_of(P.map);
    const double D = P.map.diameter;
    auto largest_change = [&](const tspline::MultiPatchResult& R, auto f) {
      double err = 0.0;
      for (std::size_t p = 0; p < R.patches.size(); ++p) {
        const auto& a = P.map.patches[p].map->control_points();
        const auto& b = R.patches[p].map->control_points();
        if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < a.size(); ++i) err = std::max(err, (b[i] - f(a[i])).norm());
      }
      return err;
    };
    const tspline::MultiPatchResult same = tspline::reparameterize_layout(old, P.domain, {}, {});
    CHECK(same.certified_valid());
    const double e0 = largest_change(same, [](const Eigen::Vector2d& x) { return x; });
    MESSAGE("no motion: largest control point change " << e0 << " (diameter " << D << ")");
    CHECK(e0 < 1e-12 * D);

    const double th = -0.9;
    Eigen::Matrix2d R;
    R << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
    const Eigen::Vector2d t(-3.0, 250.0);
    auto rigid_motion = [&](const Eigen::Vector2d& x) { return Eigen::Vector2d(R * x + t); };
    const tspline::MultiPatchResult rigid =
        tspline::reparameterize_layout(old, moved_domain(P.domain, rigid_motion), {}, {});
    CHECK(rigid.certified_valid());
    const double e1 = largest_change(rigid, rigid_motion);
    MESSAGE("rotation and translation: largest control point error " << e1);
    CHECK(e1 < 1e-11 * D);

    // A smooth motion of 4 % of the diameter: certified, conforming, same T-meshes where no refinement was needed.
    Eigen::Vector2d lo = P.domain.outer.vertices.front(), hi = lo;
    for (const auto& v : P.domain.outer.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const Eigen::Vector2d c = 0.5 * (lo + hi);
    const tspline::MultiPatchResult wavy = tspline::reparameterize_layout(
        old, moved_domain(P.domain, [&](const Eigen::Vector2d& x) {
          return Eigen::Vector2d(x.x() + 0.04 * D * std::sin(2 * M_PI * (x.y() - c.y()) / D),
                                 x.y() + 0.04 * D * std::cos(2 * M_PI * (x.x() - c.x()) / D));
        }),
        {}, {});
    CHECK(wavy.certified_valid());
    CHECK(wavy.conforming(1e-12));
    CHECK(wavy.min_mean_ratio_dense() > 0.5 * P.map.min_mean_ratio_dense());
    CHECK(std::abs(wavy.map_area - wavy.domain_area) < 1e-3 * wavy.domain_area);
    std::size_t same_tmesh = 0;
    for (std::size_t p = 0; p < wavy.patches.size(); ++p)
      same_tmesh += wavy.patches[p].map->mesh().num_cells() == P.map.patches[p].map->mesh().num_cells();
    MESSAGE("smooth motion: whole-map J_r " << wavy.min_mean_ratio_dense() << " (before "
                                            << P.map.min_mean_ratio_dense() << "), " << same_tmesh << " of "
                                            << wavy.patches.size() << " patches kept their T-mesh, gap "
                                            << wavy.max_gap() / D << " x diameter");
    // Mismatches: a hole fewer, a vertex fewer.
    tspline::Domain fewer = P.domain;
    fewer.holes.clear();
    CHECK_THROWS_WITH_AS(tspline::reparameterize_layout(old, fewer, {}, {}), doctest::Contains("rings"),
                         tspline::InputError);
    tspline::Domain shorter = P.domain;
    shorter.holes.front().vertices.pop_back(), shorter.holes.front().file_index.pop_back();
    CHECK_THROWS_WITH_AS(tspline::reparameterize_layout(old, shorter, {}, {}), doctest::Contains("hole 1"),
                         tspline::InputError);
  }

  TEST_CASE("the layout's motion: exact on the rings, the field's affine part exact inside, smooth fields followed") {
    // A disk with an off-centre hole, finely sampled (so that the moved
    // polygons are close to the field's image of the circles).
    auto circle = [](Eigen::Vector2d centre, double radius, int n) {
      Polygon p;
      for (int k = 0; k < n; ++k) {
        p.vertices.push_back(centre + radius * Eigen::Vector2d(std::cos(2 * M_PI * k / n), std::sin(2 * M_PI * k / n)));
        p.file_index.push_back(static_cast<std::size_t>(k));
      }
      return p;
    };
    const tspline::Domain d = tspline::validate_domain({circle({0, 0}, 2.0, 400), {circle({0.5, 0.3}, 0.6, 150)}});
    const double D = 4.0 * std::sqrt(2.0);
    Eigen::Vector2d lo = d.outer.vertices.front(), hi = lo;
    for (const auto& v : d.outer.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const Eigen::Vector2d c = 0.5 * (lo + hi);
    // A harmonic motion (the real and imaginary parts of z^2): the mean value
    // interpolant of its residual is close to it inside.
    auto field = [&](const Eigen::Vector2d& x) {
      const Eigen::Vector2d y = x - c;
      return Eigen::Vector2d(x + 0.02 / D * Eigen::Vector2d(y.x() * y.x() - y.y() * y.y(), 2 * y.x() * y.y()));
    };
    const tspline::Domain moved = moved_domain(d, field);
    const tspline::LayoutMotion motion(d, moved);
    // On a ring edge: the edge's own motion (linear between its moved ends).
    for (const Polygon* ring : {&d.outer, &d.holes.front()}) {
      const std::size_t n = ring->vertices.size();
      const Polygon& to = ring == &d.outer ? moved.outer : moved.holes.front();
      for (std::size_t i = 0; i < n; i += 3) {
        const Eigen::Vector2d a = ring->vertices[i], b = ring->vertices[(i + 1) % n];
        CHECK((motion(a) - to.vertices[i]).norm() < 1e-12 * D);
        CHECK((motion(a + 0.3 * (b - a)) - (0.7 * to.vertices[i] + 0.3 * to.vertices[(i + 1) % n])).norm() < 1e-12 * D);
      }
    }
    // Inside, on a grid of points: close to the field (the polygons are fine,
    // so linear interpolation between vertices hardly departs from it).
    double worst = 0.0;
    std::size_t inside = 0;
    for (int i = 1; i < 40; ++i)
      for (int j = 1; j < 40; ++j) {
        const Eigen::Vector2d x = lo + Eigen::Vector2d(i / 40.0 * (hi - lo).x(), j / 40.0 * (hi - lo).y());
        if (!tspline::domain_contains(d, x)) continue;
        ++inside;
        worst = std::max(worst, (motion(x) - field(x)).norm());
      }
    REQUIRE(inside > 500);
    MESSAGE("largest distance of the layout's motion from the field at " << inside
                                                                         << " points inside: " << worst / D
                                                                         << " x diameter");
    CHECK(worst < 5e-4 * D);  // the field moves points by up to 1e-2 D
    const Eigen::Vector2d a = d.outer.vertices[0], b = d.outer.vertices[1];
    const Eigen::Vector2d inward = Eigen::Vector2d(-(b - a).y(), (b - a).x()).normalized();  // outer ring is CCW
    const Eigen::Vector2d m = 0.5 * (a + b);
    CHECK((motion(m + 1e-7 * D * inward) - motion(m)).norm() < 1e-5 * D);
  }

  TEST_CASE("map_area: the boundary integral of x dy equals the integral of det J over the square") {
    // Against 6 x 6 Gauss points per cell (the integrand is smooth inside
    // each Bezier element; a cell with a T-junction knot line inside is
    // integrated to about 1e-7 relative).
    auto area_2d = [](const tspline::TSplineMap& map) {
      double a = 0.0;
      std::vector<tspline::QuadraturePoint> q;
      for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c) {
        q.clear();
        tspline::cell_quadrature(map.basis(), c, 6, q);
        for (const auto& p : q) a += p.weight * map.derivatives(p.uv, 1, c).J.determinant();
      }
      return a;
    };
    const auto& r = isle_of_man();
    const double a1 = tspline::map_area(*r.map), b1 = area_2d(*r.map);
    MESSAGE("Isle of Man: boundary integral " << a1 << ", area integral " << b1);
    CHECK(std::abs(a1 - b1) < 1e-7 * b1);
    for (const auto& patch : plate().map.patches) {
      const double a = tspline::map_area(*patch.map), b = area_2d(*patch.map);
      CHECK(std::abs(a - b) < 1e-7 * b);
    }
  }
}
