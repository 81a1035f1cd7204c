// Boundary: validation, corners, chord-length map (reading: test_boundary_io.cpp).
#include <doctest/doctest.h>

#include "test_support.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "tspline/boundary/boundary_map.h"
#include "tspline/boundary/corners.h"
#include "tspline/errors.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/boundary/polygon_validation.h"

using namespace tspline;
using V2 = Eigen::Vector2d;

namespace {

std::string poly_path(const std::string& name) {
  return test_support::polygon_file(name + ".txt");
}
Polygon read(const std::string& name) { return io::read_polygon(poly_path(name)); }
Polygon validated(const std::string& name) { return validate_polygon(read(name)); }

Polygon make(const std::vector<V2>& v) { return test_support::make_polygon(v); }
using test_support::contains;
using test_support::message_of;

const std::vector<std::pair<std::string, std::size_t>> kDomains = {
    {"square", 16}, {"lshape_cw", 48}, {"disk", 256},   {"flower", 400},
    {"gear", 480},  {"fjords", 800},   {"cshape", 302}, {"blob_bay", 360}};

// The message of the InputError of corners_from_file_indices(p, indices).
std::string corners_error(const Polygon& p, const std::array<long long, 4>& indices) {
  return message_of<InputError>([&] { corners_from_file_indices(p, indices); });
}

double perimeter(const Polygon& p) {
  double s = 0;
  for (std::size_t i = 0; i < p.vertices.size(); ++i)
    s += (p.vertices[(i + 1) % p.vertices.size()] - p.vertices[i]).norm();
  return s;
}

double dist_to_polygon(const Polygon& p, const V2& x) {
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = p.vertices.size();
  for (std::size_t i = 0; i < n; ++i) {
    const V2 a = p.vertices[i], d = p.vertices[(i + 1) % n] - a;
    const double t = std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + t * d - x).norm());
  }
  return best;
}

}  // namespace

TEST_SUITE("boundary") {
  // ---- reading and validating the test domains --------------------------------
  TEST_CASE("every test domain reads with its header's vertex count and validates CCW") {
    for (const auto& domain : kDomains) {
      const std::string& name = domain.first;
      const std::size_t count = domain.second;
      CAPTURE(name);
      const Polygon raw = read(name);
      CHECK(raw.vertices.size() == count);
      const Polygon p = validate_polygon(raw);
      CHECK(p.vertices.size() == count);
      CHECK(signed_area(p) > 0);
      CHECK(std::abs(signed_area(p)) == doctest::Approx(std::abs(signed_area(raw))));
    }
    CHECK(signed_area(validated("square")) == doctest::Approx(1.0));
    CHECK(signed_area(validated("lshape_cw")) == doctest::Approx(3.0));
  }

  TEST_CASE("lshape_cw is reversed to CCW and file_index travels with the vertices") {
    const Polygon raw = read("lshape_cw");
    CHECK(signed_area(raw) == doctest::Approx(-3.0));
    const Polygon p = validate_polygon(raw);
    CHECK(signed_area(p) == doctest::Approx(3.0));
    REQUIRE(p.file_index.size() == 48);
    CHECK(p.file_index[0] == 47);
    CHECK(p.file_index[47] == 0);
    for (std::size_t i = 0; i < 48; ++i) CHECK(p.vertices[i] == raw.vertices[p.file_index[i]]);
    // Square was already CCW: unchanged.
    const Polygon sq = validated("square");
    for (std::size_t i = 0; i < 16; ++i) CHECK(sq.file_index[i] == i);
  }

  TEST_CASE("error: 3 vertices") {
    const Polygon p = io::parse_polygon("0 0\n1 0\n0 1\n", "t.txt");
    CHECK(contains(message_of<InputError>([&] { validate_polygon(p); }), "3 vertices; at least 4"));
  }

  TEST_CASE("error: duplicate consecutive vertices") {
    const Polygon p = io::parse_polygon("0 0\n1 0\n1 0\n1 1\n0 1\n", "d.txt");
    CHECK(
        contains(message_of<InputError>([&] { validate_polygon(p); }), "vertices 1 and 2 are equal (1, 0)"));
  }

  TEST_CASE("error: self-intersecting bow-tie") {
    const Polygon p = make({V2(0, 0), V2(1, 1), V2(1, 0), V2(0, 1)});
    CHECK(message_of<InputError>([&] { validate_polygon(p); })
              .starts_with("polygon is not simple: edges 0-1 and 2-3 intersect near (0.5, 0.5); "));
  }

  TEST_CASE("error: crossing between edges far apart in the numbering, named by file indices") {
    Polygon p = read("square");
    p.vertices[10] = V2(0.5, -0.5);  // top vertex pulled below the bottom side
    const std::string msg = message_of<InputError>([&] { validate_polygon(p); });
    CHECK(contains(msg, "polygon is not simple: edges 1-2 and 10-11 intersect near (0.41666"));
    CHECK(contains(msg, "(1 more conflicting edge pair(s))"));  // edges 2-3 and 9-10
    // Same polygon stored clockwise: the names are still the file's numbering.
    Polygon cw = p;
    std::reverse(cw.vertices.begin(), cw.vertices.end());
    for (std::size_t i = 0; i < 16; ++i) cw.file_index[i] = 15 - i;
    CHECK(contains(message_of<InputError>([&] { validate_polygon(cw); }), "edges 11-10 and 2-1 intersect"));
  }

  TEST_CASE("error: edges folding back on each other (collinear overlap)") {
    const Polygon p = make({V2(0, 0), V2(2, 0), V2(1, 0), V2(1, 1)});
    CHECK(contains(message_of<InputError>([&] { validate_polygon(p); }),
                   "edges 0-1 and 1-2 overlap near (1, 0)"));
  }

  TEST_CASE("error: zero area (all collinear)") {
    const Polygon p = make({V2(0, 0), V2(1, 1), V2(2, 2), V2(3, 3)});
    CHECK(message_of<InputError>([&] { validate_polygon(p); }) ==
          "polygon has zero area (all vertices are collinear)");
  }

  TEST_CASE("error: corner index out of range") {
    const Polygon p = validated("square");
    CHECK(contains(corners_error(p, {0, 16, 8, 12}),
                   "corner 2: vertex index 16 is out of range (the file has vertices 0..15)"));
    CHECK(contains(corners_error(p, {-1, 4, 8, 12}), "corner 1: vertex index -1 is out of range"));
  }

  TEST_CASE("error: corner index repeated") {
    const Polygon p = validated("square");
    CHECK(contains(corners_error(p, {0, 4, 4, 12}), "corner 3: vertex index 4 is repeated (also corner 2)"));
  }

  TEST_CASE("error: corners not in cyclic order") {
    const Polygon p = validated("square");
    CHECK(contains(corners_error(p, {0, 8, 4, 12}), "corner 3: vertex index 4 is out of cyclic order"));
    CHECK(contains(corners_error(p, {12, 8, 4, 0}), "corner 3: vertex index 4 is out of cyclic order"));
  }

  // ---- corners -----------------------------------------------------------------

  TEST_CASE("user corners: cyclic rotation accepted; clockwise file traversed in reverse") {
    const Polygon sq = validated("square");
    const Corners c = corners_from_file_indices(sq, {8, 12, 0, 4});
    CHECK(c.index == std::array<std::size_t, 4>{8, 12, 0, 4});
    for (double a : c.inner_angle_deg) CHECK(a == doctest::Approx(90.0));
    const Polygon l = validated("lshape_cw");
    const Corners cl = corners_from_file_indices(l, {7, 15, 39, 47});
    // CCW from file vertex 7 = (0,2): 47 (0,0), 39 (2,0), 15 (1,2).
    std::array<std::size_t, 4> fi{};
    for (int k = 0; k < 4; ++k) fi[k] = l.file_index[cl.index[k]];
    CHECK(fi == std::array<std::size_t, 4>{7, 47, 39, 15});
    CHECK(l.vertices[cl.index[0]] == V2(0, 2));
    CHECK(!cl.explanation.empty());
  }

  TEST_CASE("choose_corners: square -> its four 90-degree corners") {
    const Polygon p = validated("square");
    const Corners c = choose_corners(p);
    std::array<std::size_t, 4> fi{};
    for (int k = 0; k < 4; ++k) fi[k] = p.file_index[c.index[k]];
    CHECK(fi == std::array<std::size_t, 4>{0, 4, 8, 12});
    for (double a : c.inner_angle_deg) CHECK(a == doctest::Approx(90.0));
    CHECK(contains(c.explanation, "0, 4, 8, 12"));
  }

  TEST_CASE("choose_corners: L-shape -> four convex 90-degree vertices") {
    const Polygon p = validated("lshape_cw");
    const Corners c = choose_corners(p);
    for (int k = 0; k < 4; ++k) {
      CHECK(c.inner_angle_deg[k] == doctest::Approx(90.0));
      const std::size_t f = p.file_index[c.index[k]];
      CHECK((f == 7 || f == 15 || f == 31 || f == 39 || f == 47));  // 23 is the reflex corner
    }
  }

  TEST_CASE("choose_corners: C-shape -> its four 90-degree corners, not points on the arcs") {
    const Polygon p = validated("cshape");
    const Corners c = choose_corners(p);
    std::vector<std::size_t> fi;
    for (std::size_t i : c.index) fi.push_back(p.file_index[i]);
    std::sort(fi.begin(), fi.end());
    CHECK(fi == std::vector<std::size_t>{0, 150, 151, 301});
  }

  TEST_CASE("choose_corners: disk -> chains of nearly equal length") {
    const Polygon p = validated("disk");
    const BoundaryMap m(p, choose_corners(p));
    const double quarter = perimeter(p) / 4;
    for (int s = 0; s < 4; ++s) CHECK(std::abs(m.chain_length(Side(s)) - quarter) <= 0.25 * quarter);
  }

  TEST_CASE("choose_corners: every test domain -> four distinct convex vertices, deterministic") {
    for (const auto& domain : kDomains) {
      const std::string& name = domain.first;
      CAPTURE(name);
      const Polygon p = validated(name);
      const Corners c = choose_corners(p);
      int descents = 0;  // distinct and in CCW order <=> exactly one cyclic descent
      for (int k = 0; k < 4; ++k) {
        CHECK(c.inner_angle_deg[k] < 180.0);
        descents += c.index[(k + 1) % 4] <= c.index[k];
      }
      CHECK(descents == 1);
      CHECK(!c.explanation.empty());
      CHECK(choose_corners(p).index == c.index);
      CHECK_NOTHROW(BoundaryMap(p, c));
    }
  }

  // ---- chord-length map ------------------------------------------------------------

  TEST_CASE("chord map on the square: corners, vertex params, points, vertices_between") {
    const Polygon p = validated("square");
    const BoundaryMap m(p, corners_from_file_indices(p, {0, 4, 8, 12}));
    const V2 corner[4] = {V2(0, 0), V2(1, 0), V2(1, 1), V2(0, 1)};
    for (int s = 0; s < 4; ++s) {
      CHECK(m.point(Side(s), 0.0) == corner[s]);
      CHECK(m.point(Side(s), 1.0) == corner[(s + 1) % 4]);
      CHECK(m.chain_params(Side(s)) == std::vector<double>{0, 0.25, 0.5, 0.75, 1});
      CHECK(m.chain_length(Side(s)) == 1.0);
      CHECK(m.chain_points(Side(s)).size() == 5);
    }
    CHECK(m.point(Side::Bottom, 0.3).isApprox(V2(0.3, 0)));
    CHECK(m.point(Side::Top, 0.25) == V2(0.75, 1));
    CHECK(m.point_at(V2(0, 0)) == V2(0, 0));
    CHECK(m.point_at(V2(1, 1)) == V2(1, 1));
    CHECK(m.point_at(V2(1, 0.5)) == V2(1, 0.5));
    CHECK(m.point_at(V2(0.25, 1)) == V2(0.25, 1));
    CHECK(m.point_at(V2(0, 0.75)) == V2(0, 0.75));
    CHECK_THROWS_AS(m.point_at(V2(0.5, 0.5)), std::invalid_argument);
    CHECK_THROWS_AS(m.point(Side::Left, 1.5), std::invalid_argument);
    using R = std::pair<std::size_t, std::size_t>;
    CHECK(m.vertices_between(Side::Bottom, 0.25, 0.75) == R{2, 3});  // strictly inside
    CHECK(m.vertices_between(Side::Bottom, 0.2, 0.8) == R{1, 4});
    CHECK(m.vertices_between(Side::Right, 0.0, 1.0) == R{1, 4});
    CHECK(m.vertices_between(Side::Top, 0.3, 0.45) == R{2, 2});
  }

  TEST_CASE(
      "chord map on the disk and the L-shape: params are cumulative length / total, points on the polygon") {
    for (const char* name : {"disk", "lshape_cw", "fjords"}) {
      CAPTURE(name);
      const Polygon p = validated(name);
      const Corners c = choose_corners(p);
      const BoundaryMap m(p, c);
      double total = 0;
      for (int s = 0; s < 4; ++s) {
        const Side side = Side(s);
        const auto& pts = m.chain_points(side);
        const auto& par = m.chain_params(side);
        CHECK(pts.front() == p.vertices[c.index[s]]);
        CHECK(pts.back() == p.vertices[c.index[(s + 1) % 4]]);
        CHECK(m.point(side, 0.0) == pts.front());
        CHECK(m.point(side, 1.0) == pts.back());
        double len = 0;
        for (std::size_t k = 0; k < pts.size(); ++k) {
          if (k) len += (pts[k] - pts[k - 1]).norm();
          CHECK(par[k] == doctest::Approx(len / m.chain_length(side)).epsilon(1e-14));
          CHECK(m.point(side, par[k]) == pts[k]);  // exact at vertices
          if (k) CHECK(par[k] > par[k - 1]);
        }
        total += m.chain_length(side);
        for (int j = 1; j < 50; ++j) CHECK(dist_to_polygon(p, m.point(side, j / 50.0)) < 1e-12);
      }
      CHECK(total == doctest::Approx(perimeter(p)));
    }
  }

  TEST_CASE("large noisy polygon (50k vertices) validates and gets corners") {
    std::vector<V2> v;
    const int n = 50000;
    for (int i = 0; i < n; ++i) {
      const double t = 2 * std::numbers::pi * i / n, r = 1 + 0.01 * std::sin(977.0 * t);
      v.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    const Polygon p = validate_polygon(make(v));
    const Corners c = choose_corners(p);
    const BoundaryMap m(p, c);
    const double quarter = perimeter(p) / 4;
    for (int s = 0; s < 4; ++s) CHECK(std::abs(m.chain_length(Side(s)) - quarter) <= 0.25 * quarter);
  }

}  // TEST_SUITE
