// Local submesh templates (Brovka 2013 Eqs. 4-5) and the Appendix's properties.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <Eigen/LU>
#include <map>

#include "meshopt/local_objective.h"
#include "meshopt/node_smoother.h"
#include "tspline/tmesh/tmesh.h"
#include "tspline/detail/tmesh_submesh.h"
#include "tspline/tmesh/smoothing_problem.h"

using tspline::TMesh;

namespace {

constexpr std::int64_t R = TMesh::kRoot;

int vertex_at(const TMesh& m, double x, double y) {
  return m.find_vertex({static_cast<std::int64_t>(x * R), static_cast<std::int64_t>(y * R)});
}

// Physical positions: the parametric mesh stretched by diag(a, b) (an
// "orthogonal" physical mesh: every cell a rectangle).
std::vector<Eigen::Vector2d> stretched(const TMesh& m, double a, double b) {
  std::vector<Eigen::Vector2d> x(m.num_vertices());
  for (int v = 0; v < static_cast<int>(x.size()); ++v) x[v] = m.vertex_param(v).cwiseProduct(Eigen::Vector2d(a, b));
  return x;
}

std::map<double, int> weight_histogram(const std::vector<meshopt::LocalTriangle>& tris) {
  std::map<double, int> h;
  for (const auto& t : tris) ++h[t.weight];
  return h;
}

// Regular vertex (1/2, 1/2) surrounded by cells of sizes 1/8, 1/4, 1/2, 1/4 (scales 1:2:4:2).
TMesh regular_124_mesh() {
  TMesh m(1);
  const int sw = m.refine(m.leaf_at_doubled(R / 2, R / 2));  // SW quarter -> 1/4 cells
  m.refine(sw + 3);                                           // its NE child -> 1/8 cells
  m.refine(m.leaf_at_doubled(3 * R / 2, R / 2));              // SE quarter -> 1/4
  m.refine(m.leaf_at_doubled(R / 2, 3 * R / 2));              // NW quarter -> 1/4
  m.balance();
  m.build_topology();
  return m;
}

// Hanging vertex (1/2, 3/4) on the right edge of the NW cell (size 1/2).
TMesh hanging_mesh() {
  TMesh m(1);
  m.refine(m.leaf_at_doubled(3 * R / 2, 3 * R / 2));  // NE quarter -> 1/4 cells
  m.balance();
  m.build_topology();
  return m;
}

// The local submesh of the vertex at (x, y), required to exist and to be
// hanging or not as `hanging` says.
std::vector<meshopt::LocalTriangle> submesh_of_vertex_at(const TMesh& m, double x, double y, bool hanging) {
  const int v = vertex_at(m, x, y);
  REQUIRE(v >= 0);
  REQUIRE(m.vertex_is_hanging(v) == hanging);
  return tspline::detail::local_submesh(m, v);
}

double optimum_distance(const TMesh& m, int v, const std::vector<Eigen::Vector2d>& x, bool weighted) {
  const auto tris = tspline::detail::local_submesh(m, v, weighted);
  meshopt::SmoothingOptions opt;
  opt.newton_iterations_per_visit = 100;
  Eigen::Vector2d p = x[v] + Eigen::Vector2d(0.03, -0.02);
  for (int k = 0; k < 20; ++k) p = meshopt::optimize_node(p, x, tris, opt);
  return (p - x[v]).norm();
}

}  // namespace

TEST_SUITE("tmesh_submesh") {
  TEST_CASE("regular vertex in a uniform mesh: 12 triangles of weight 1") {
    TMesh m(2);
    m.build_topology();
    const int v = vertex_at(m, 0.5, 0.5);
    const auto tris = tspline::detail::local_submesh(m, v);
    CHECK(tris.size() == 12);
    CHECK(weight_histogram(tris) == std::map<double, int>{{1.0, 12}});
    // Every ideal triangle is counter-clockwise: det W > 0.
    for (const auto& t : tris) CHECK(t.ideal_inv.determinant() > 0.0);
  }

  TEST_CASE("regular vertex with cells of scale 1:2:4 gets weights 1, 2, 4 (Eq. 4)") {
    const auto tris = submesh_of_vertex_at(regular_124_mesh(), 0.5, 0.5, /*hanging=*/false);
    CHECK(tris.size() == 12);
    CHECK(weight_histogram(tris) == std::map<double, int>{{1.0, 3}, {2.0, 6}, {4.0, 3}});
  }

  TEST_CASE("hanging vertex: 11 triangles, the T-junction cell's 5 weighted 8/5 (Eq. 5)") {
    const auto tris = submesh_of_vertex_at(hanging_mesh(), 0.5, 0.75, /*hanging=*/true);
    CHECK(tris.size() == 11);
    CHECK(weight_histogram(tris) == std::map<double, int>{{1.0, 6}, {1.6, 5}});
    for (const auto& t : tris) CHECK(t.ideal_inv.determinant() > 0.0);
  }

  TEST_CASE("Appendix, regular vertex: weighted optimum of a 1:2:4 orthogonal mesh is orthogonal") {
    const TMesh m = regular_124_mesh();
    const int v = vertex_at(m, 0.5, 0.5);
    for (const std::pair<double, double>& ab : {std::pair{1.0, 1.0}, std::pair{1.0, 2.0}, std::pair{3.0, 0.7}}) {
      const double a = ab.first, b = ab.second;
      CAPTURE(a);
      CAPTURE(b);
      const auto x = stretched(m, a, b);
      CHECK(optimum_distance(m, v, x, true) < 1e-9);
      // Unweighted K* pulls the node towards the small cell unless the mesh is
      // similar to the parametric one (a == b: every triangle ideal).
      if (a != b) CHECK(optimum_distance(m, v, x, false) > 1e-3);
    }
  }

  TEST_CASE("Appendix, hanging vertex: weighted optimum is orthogonal for any a != b") {
    const TMesh m = hanging_mesh();
    const int v = vertex_at(m, 0.5, 0.75);
    for (const std::pair<double, double>& ab : {std::pair{1.0, 2.0}, std::pair{2.0, 1.0}, std::pair{0.5, 1.3}, std::pair{3.0, 1.0}}) {
      const double a = ab.first, b = ab.second;
      CAPTURE(a);
      CAPTURE(b);
      const auto x = stretched(m, a, b);
      CHECK(optimum_distance(m, v, x, true) < 1e-9);
      CHECK(optimum_distance(m, v, x, false) > 1e-3);
      // The gradient of the weighted objective vanishes at the orthogonal position.
      const auto g = meshopt::local_objective(x[v], x, tspline::detail::local_submesh(m, v, true), 0.0).gradient;
      CHECK(g.norm() < 1e-12 * (1.0 + std::abs(a) + std::abs(b)) * 100);
    }
  }

  TEST_CASE("build_smoothing_problem frees exactly the interior vertices") {
    const TMesh m = regular_124_mesh();
    const auto prob = tspline::build_smoothing_problem(m);
    std::size_t interior = 0;
    for (int v = 0; v < static_cast<int>(m.num_vertices()); ++v) interior += m.vertex_on_boundary(v) ? 0 : 1;
    CHECK(prob.size() == interior);
    for (std::size_t k = 0; k < prob.size(); ++k) {
      const auto n = prob.triangles_of(k).size();
      CHECK((n == 12 || n == 11));
    }
  }
}
