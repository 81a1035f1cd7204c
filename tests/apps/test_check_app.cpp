// `tspline check` run as a separate process on T-spline files with known
// answers (certified, folded between Gauss points, undecided at a small depth),
// bad input, and the certification fields of the `tspline param` report.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "separable_maps.h"
#include "test_support.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/tspline_file.h"

namespace fs = std::filesystem;
using test_support::contains;
using test_support::count_lines;
using test_support::run_app;
using test_support::slurp;

namespace {

fs::path scratch(const std::string& name) { return test_support::scratch_dir("check_app", name); }

std::string write_map(const fs::path& dir, const std::string& name, const tspline::TSplineMap& map) {
  tspline::io::TSplineFileMeta meta;
  meta.source = name;
  const fs::path file = dir / (name + ".json");
  tspline::io::write_tspline_file(file.string(), map, meta);
  std::string quoted = "'";  // (appending avoids a GCC 12 -Wrestrict false positive on "'" + string)
  quoted += file.string();
  quoted += "'";
  return quoted;
}

}  // namespace

TEST_SUITE("check_app") {
  TEST_CASE("check: a distorted square is certified (exit 0), the summary counts its elements") {
    const fs::path d = scratch("ok");
    tspline::TSplineMap map = tspline::greville_identity_map(test_support::uniform_mesh(2));
    std::vector<Eigen::Vector2d> P = map.control_points();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.02, 0.02);
    for (Eigen::Vector2d& p : P)
      if (p.x() > 0.0 && p.x() < 1.0 && p.y() > 0.0 && p.y() < 1.0) p += Eigen::Vector2d(u(rng), u(rng));
    map.set_control_points(P);
    const auto r = run_app("check " + write_map(d, "square", map), d);
    CAPTURE(r.out);
    CAPTURE(r.err);
    CHECK(r.exit_code == 0);
    CHECK(r.err.empty());
    CHECK(contains(r.out, "cells: 16\n"));
    CHECK(contains(r.out, "bezier elements: 16\n"));
    CHECK(contains(r.out, "certified: 16 of 16 elements"));
    CHECK(contains(r.out, "det J > 0 proven false: 0 elements\n"));
    CHECK(contains(r.out, "result: certified valid"));
    // Only inner control points moved: the corners keep the square's right
    // angles and equal speeds, whatever the inside does.
    CHECK(contains(r.out, "scaled Jacobian at the worst corner of the square, which the boundary fixes: 1 (J_r 1; "
                          "interior angle 90.0 degrees"));
  }

  TEST_CASE("check: a map folded between the Gauss points fails (exit 3), naming the element and the point") {
    const fs::path d = scratch("fold");
    const tspline::TSplineMap map = test_support::fold_between_gauss_points();
    const auto r = run_app("check " + write_map(d, "fold", map), d);
    CAPTURE(r.out);
    CHECK(r.exit_code == 3);
    CHECK(count_lines(r.err) == 1);
    CHECK(contains(r.err, "not certified valid: 1 of 1 elements not certified (1 with det J < 0 proven"));
    CHECK(contains(r.out, "result: NOT certified valid"));
    CHECK(contains(r.out, "det J > 0 proven false: 1 elements\n"));
    // The failing element, its bounds, and a parametric point in the fold strip |u - 1/2| < 0.1.
    const std::string head = "cell 0 element [0, 1] x [0, 1]: det J = ";
    REQUIRE(contains(r.out, head));
    const std::string line = r.out.substr(r.out.find(head));
    double det = 0.0, u = 0.0, v = 0.0;
    REQUIRE(std::sscanf(line.c_str() + head.size(), "%lf < 0 at (u, v) = (%lf, %lf)", &det, &u, &v) == 3);
    CHECK(det < 0.0);
    CHECK(std::abs(u - 0.5) < 0.1);
    CHECK(det == doctest::Approx(map.jacobian({u, v}).determinant()).epsilon(1e-6));
  }

  TEST_CASE("check of a multi-patch file with a folded patch: the whole map's counts, the patch and its element") {
    // Patch 0 the identity of the square (16 elements), patch 1 folded between
    // its Gauss points (one element, det J < 0 proven).
    const fs::path d = scratch("multi_fold");
    const tspline::TSplineMap good = tspline::greville_identity_map(test_support::uniform_mesh(2));
    const tspline::TSplineMap fold = test_support::fold_between_gauss_points();
    std::vector<tspline::io::TSplineFileMeta> metas(2);
    metas[0].source = metas[1].source = "two";
    const fs::path file = d / "two.json";
    tspline::io::write_multipatch_file(file.string(), {&good, &fold}, metas, {}, {}, "two");
    const auto r = run_app("check '" + file.string() + "'", d);
    CAPTURE(r.out);
    CHECK(r.exit_code == 3);
    CHECK(count_lines(r.err) == 1);
    CHECK(contains(r.err, "not certified valid: 1 of 17 elements not certified (1 with det J < 0 proven"));
    CHECK(contains(r.out, "patches: 2\n"));
    CHECK(contains(r.out, "certified: 16 of 17 elements, 1 of 2 patches"));
    CHECK(contains(r.out, "det J > 0 proven false: 1 elements\n"));
    CHECK(contains(r.out, "patch 1: NOT certified valid (0 of 1 elements certified)\ncell 0 element [0, 1] x [0, 1]: det J = "));
    CHECK_FALSE(contains(r.out, "patch 0: NOT"));
    // The folded patch is the worst, and said to be uncertified; the identity's J_r is 1.
    CHECK(contains(r.out, "worst patches (by the certified J_r bound):\n  patch 1: 1 cells, J_r >= -"));
    CHECK(contains(r.out, "NOT certified\n  patch 0: 16 cells, J_r >= 1,"));
    CHECK(contains(r.out, "result: NOT every patch certified valid"));
    // --per-patch: both patches' own blocks, then the whole map's.
    const auto all = run_app("check '" + file.string() + "' --per-patch --worst 0", d);
    CHECK(all.exit_code == 3);
    CHECK(contains(all.out, "patch 0:\ncells: 16\nbezier elements: 16\n"));
    CHECK(contains(all.out, "patch 1:\ncells: 1\n"));
    CHECK(contains(all.out, "result: NOT certified valid (1 cells affected)"));
    CHECK(contains(all.out, "whole map:\npatches: 2\n"));
    CHECK_FALSE(contains(all.out, "worst patches"));
  }

  TEST_CASE("check --depth: det J touching zero is undecided, not certified") {
    const fs::path d = scratch("undecided");
    // S = (u, v^3): det J = 3 v^2, zero on the edge v = 0.
    const tspline::TSplineMap map =
        test_support::separable_cubic_map(test_support::uniform_mesh(0), {0, 1, 0, 0}, {0, 0, 0, 1});
    const auto r = run_app("check " + write_map(d, "cubic", map) + " --depth 3", d);
    CAPTURE(r.out);
    CHECK(r.exit_code == 3);
    CHECK(contains(r.out, "undecided at the depth limit: 1 elements"));
    CHECK(contains(r.out, "cell 0 element [0, 1] x [0, 1]: undecided at depth 3"));
    CHECK(contains(r.err, "0 with det J < 0 proven, 1 undecided"));
  }

  TEST_CASE("check: bad input gives one error line and exit 1 / 2") {
    const fs::path d = scratch("bad");
    std::ofstream(d / "bad.json") << "{\"format\": \"tspline\", \"version\": 99}";
    const std::string ok = write_map(d, "id", tspline::greville_identity_map(test_support::uniform_mesh(1)));
    const std::vector<test_support::BadInvocation> cases{
        {"check '" + (d / "missing.json").string() + "'", "missing.json", 2},
        {"check '" + (d / "bad.json").string() + "'", "/version: unsupported version 99", 1},
        {"check", "TSPLINE", 1},
        {"check " + ok + " --depth 99", "--depth", 1},
        {"check " + ok + " --depth x", "--depth", 1},
    };
    for (const test_support::BadInvocation& c : cases) test_support::check_bad_invocation(c, d);
    const auto h = run_app("check --help", d);
    CHECK(h.exit_code == 0);
    CHECK(contains(h.out, "--depth"));
    CHECK(contains(h.out, "--max-listed"));
  }

  TEST_CASE(
      "param: the report says certified_valid, with the counts and the bound; check agrees on tspline.json") {
    const fs::path d = scratch("param");
    const fs::path map = test_support::param_polygon("disk.txt", d / "out", "--layout single");
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["certified_valid"] == true);
    const auto& c = rep["certification"];
    CHECK(c["elements"].get<int>() > 0);
    CHECK(c["elements_certified"] == c["elements"]);
    CHECK(c["elements_invalid"] == 0);
    CHECK(c["elements_undecided"] == 0);
    CHECK(c["min_relative_det_lower_bound"].get<double>() > 0.0);
    CHECK(c["min_relative_det_lower_bound"].get<double>() <= 1.0);
    CHECK(c["min_det_lower_bound"].get<double>() > 0.0);
    CHECK(c["depth_limit"] == 8);
    CHECK(rep["seconds"].contains("certification"));
    const auto& its = rep["adaptive"]["iterations"];
    REQUIRE(its.size() >= 1);
    // The kept map comes from the global untangling, certified there.
    const auto& u = its[rep["adaptive"]["kept_iteration"].get<int>()]["untangling"];
    CHECK(u["certified"] == true);
    CHECK(u["after"]["nonpositive"] == 0);
    CHECK(u["free_points"].get<int>() > 0);
    for (const auto& it : its) CHECK(it["certification"].contains("elements_certified"));
    const auto k = run_app("check '" + map.string() + "'", d);
    CHECK(k.exit_code == 0);
    CHECK(contains(k.out, "certified: " + std::to_string(c["elements"].get<int>()) + " of "));
    const auto h = run_app("param --help", d);
    CHECK(contains(h.out, "--cert-depth"));
  }
}
