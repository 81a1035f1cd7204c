// Bezier extraction export (docs/bezier_format.md): on T-meshes with hanging
// vertices, the rational Bezier patches and the extraction rows of every
// element reproduce the T-spline map at random points to round-off; the file
// round-trips through JSON; `tspline export` writes it.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <random>

#include "test_support.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/io/bezier_export.h"
#include "tspline/io/polygon_reader.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// Max |S_bezier - S| / diameter over random points of every element, for both
/// forms in the document: the homogeneous Bezier points and the extraction rows
/// with the global control points.
std::pair<double, double> reproduction_error(const json& doc, const tspline::TSplineMap& map, double diameter) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  double worst_h = 0.0, worst_c = 0.0;
  const json& P = doc["control_points"];
  for (const json& e : doc["elements"]) {
    const Eigen::Vector2d lo(e["lo"][0].get<double>(), e["lo"][1].get<double>());
    const Eigen::Vector2d hi(e["hi"][0].get<double>(), e["hi"][1].get<double>());
    for (int trial = 0; trial < 3; ++trial) {
      const double s = u01(rng), t = u01(rng);
      const auto bs = tspline::bernstein3(s), bt = tspline::bernstein3(t);
      // Homogeneous form.
      Eigen::Vector3d h = Eigen::Vector3d::Zero();
      for (int k = 0; k < 16; ++k) {
        const json& Hk = e["bezier_points_homogeneous"][k];
        h += bs[k % 4] * bt[k / 4] * Eigen::Vector3d(Hk[0].get<double>(), Hk[1].get<double>(), Hk[2].get<double>());
      }
      // Extraction rows.
      Eigen::Vector2d X = Eigen::Vector2d::Zero();
      double w = 0.0;
      for (std::size_t r = 0; r < e["functions"].size(); ++r) {
        double N = 0.0;
        for (int k = 0; k < 16; ++k) N += e["extraction"][r][k].get<double>() * bs[k % 4] * bt[k / 4];
        const json& p = P[e["functions"][r].get<std::size_t>()];
        X += N * Eigen::Vector2d(p[0].get<double>(), p[1].get<double>());
        w += N;
      }
      const Eigen::Vector2d uv = lo + Eigen::Vector2d(s * (hi.x() - lo.x()), t * (hi.y() - lo.y()));
      const Eigen::Vector2d S = map.point(uv);
      worst_h = std::max(worst_h, (h.head<2>() / h.z() - S).norm() / diameter);
      worst_c = std::max(worst_c, (X / w - S).norm() / diameter);
    }
  }
  return {worst_h, worst_c};
}

}  // namespace

TEST_SUITE("bezier_export") {
  TEST_CASE("every element reproduces the map on T-meshes with hanging vertices") {
    for (const char* domain : {"flower.txt", "gear.txt"}) {
      CAPTURE(domain);
      const auto poly = tspline::io::read_polygon(test_support::polygon_file(domain));
      const tspline::ParameterizationResult r = tspline::run_parameterization(poly, {}, {});
      REQUIRE(r.map.has_value());
      REQUIRE(r.map->mesh().num_hanging_vertices() > 0);
      const json doc = json::parse(tspline::io::bezier_document(*r.map, domain).dump());  // through text
      CHECK(doc["format"] == "tspline-bezier");
      CHECK(doc["control_points"].size() == r.map->basis().size());
      // Some cell is split into several elements (knot lines crossing it).
      CHECK(doc["elements"].size() > r.map->mesh().num_cells());
      // The elements tile the square: their areas sum to 1.
      double area = 0.0;
      for (const json& e : doc["elements"])
        area += (e["hi"][0].get<double>() - e["lo"][0].get<double>()) * (e["hi"][1].get<double>() - e["lo"][1].get<double>());
      CHECK(area == doctest::Approx(1.0).epsilon(1e-15));
      double diameter = 0.0;
      for (const auto& v : poly.vertices) diameter = std::max(diameter, (v - poly.vertices[0]).norm());
      const auto [eh, ec] = reproduction_error(doc, *r.map, diameter);
      MESSAGE(std::string(domain) << ": " << doc["elements"].size() << " elements on " << r.map->mesh().num_cells()
                     << " cells; max |S_bezier - S| / diameter: homogeneous " << eh << ", extraction " << ec);
      CHECK(eh <= 1e-13);
      CHECK(ec <= 1e-13);
    }
  }

  TEST_CASE("tspline export --bezier: file and bad input") {
    const fs::path d = test_support::scratch_dir("bezier_export", "app");
    const fs::path map = test_support::param_polygon("disk.txt", d / "disk", "--layout single");
    const fs::path out = d / "disk_bezier.json";
    const auto r = test_support::require_success(
        test_support::run_app("export " + test_support::quoted(map) + " --bezier " + test_support::quoted(out), d));
    CHECK(test_support::contains(r.out, "Bezier elements"));
    const json doc = json::parse(test_support::slurp(out));
    CHECK(doc["version"] == 1);
    CHECK(!doc["elements"].empty());
    // A map that does not exist: exit 2, one line naming it.
    test_support::check_bad_invocation(
        {"export " + test_support::quoted(d / "nonesuch.json") + " --bezier " + test_support::quoted(d / "x.json"),
         "nonesuch.json", 2},
        d);
    CHECK(!fs::exists(d / "x.json"));
  }
}
