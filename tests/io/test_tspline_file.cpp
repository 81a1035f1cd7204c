// The T-spline file (docs/tspline_format.md): bit-identical write/read round
// trips, the documented fields, every malformed-file case, and the `tspline
// eval` / `tspline info` subcommands run as a separate process.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "test_support.h"

#include "tspline/errors.h"
#include "tspline/io/tspline_file.h"

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::contains;
using tspline::TMesh;
using tspline::TSplineMap;
using tspline::io::LoadedTSpline;
using tspline::io::read_tspline_file;
using tspline::io::TSplineFileMeta;
using tspline::io::write_tspline_file;

namespace {

fs::path scratch(const std::string& name) { return test_support::scratch_dir("file_test", name); }
using test_support::count_lines;
using test_support::run_app;
using test_support::slurp;
using RunResult = test_support::AppRun;

void spit(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }

TMesh uniform(int level) {
  TMesh m(level);
  m.build_topology();
  return m;
}

// Uniform level-`level` mesh, then `splits` random refinements (leaves below
// level 7) and a balance.
TMesh make_mesh(int level, int splits, unsigned seed) {
  return test_support::random_leaf_splits(level, splits, seed, /*max_level=*/7);
}

// Control points from a smooth nonlinear function of each interpolation point.
TSplineMap make_map(TMesh mesh) {
  const tspline::TSplineBasis basis(mesh);
  std::vector<Eigen::Vector2d> cps;
  for (const auto& f : basis.functions()) {
    const Eigen::Vector2d p = f.interpolation_point;
    cps.emplace_back(3.0 * p.x() + 0.2 * std::sin(3.0 * p.y()) + 1.0 / 3.0,
                     2.0 * p.y() + 0.1 * std::cos(2.0 * p.x()) + 0.05 * p.x() * p.x() - 1e-7);
  }
  return TSplineMap(std::move(mesh), std::move(cps));
}

TSplineFileMeta square_meta() {
  TSplineFileMeta meta;
  meta.source = "square \"test\".txt";
  meta.boundary = test_support::make_polygon({{1.0 / 3, -0.1}, {3.2, 0.1}, {3.3, 2.1}, {0.3, 2.0}, {0.2, 1.0}});
  meta.boundary.file_index = {4, 0, 1, 2, 3};
  meta.corners = {0, 1, 2, 3};
  return meta;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// S, J and the second derivatives agree bit for bit at many points.
void check_same_map(const TSplineMap& a, const TSplineMap& b) {
  REQUIRE(a.control_points().size() == b.control_points().size());
  for (std::size_t k = 0; k < a.control_points().size(); ++k) {
    CHECK(same_bits(a.control_points()[k].x(), b.control_points()[k].x()));
    CHECK(same_bits(a.control_points()[k].y(), b.control_points()[k].y()));
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<Eigen::Vector2d> pts{{0, 0}, {1, 1}, {1, 0}, {0.5, 1}, {0.25, 0.375}};
  for (int k = 0; k < 400; ++k) pts.emplace_back(U(rng), U(rng));
  int mismatches = 0;
  for (const auto& uv : pts) {
    const auto da = a.derivatives(uv, 2), db = b.derivatives(uv, 2);
    mismatches += !(da.x == db.x && da.J == db.J && da.xixi == db.xixi && da.xieta == db.xieta &&
                    da.etaeta == db.etaeta && a.point(uv) == b.point(uv));
  }
  CHECK(mismatches == 0);
}

LoadedTSpline round_trip(const TSplineMap& map, const TSplineFileMeta& meta, const fs::path& dir) {
  const fs::path p = dir / "tspline.json";
  write_tspline_file(p.string(), map, meta);
  LoadedTSpline back = read_tspline_file(p.string());
  CHECK(back.map.mesh().num_cells() == map.mesh().num_cells());
  CHECK(back.map.mesh().num_vertices() == map.mesh().num_vertices());
  CHECK(back.map.basis().size() == map.basis().size());
  check_same_map(map, back.map);
  CHECK(back.meta.source == meta.source);
  CHECK(back.meta.boundary.vertices == meta.boundary.vertices);
  CHECK(back.meta.boundary.file_index == meta.boundary.file_index);
  CHECK(back.meta.corners == meta.corners);
  return back;
}

// ---------------------------------------------------------------- app runs
std::string g17(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

TEST_SUITE("tspline_file") {
  TEST_CASE("round trip on a uniform mesh is bit-identical") {
    const fs::path dir = scratch("uniform");
    const TSplineMap map = make_map(uniform(3));
    round_trip(map, square_meta(), dir);
    // Only the target file remains: no temporary left behind.
    CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
  }

  TEST_CASE("round trip on an adaptive T-mesh with hanging vertices is bit-identical") {
    for (unsigned seed : {1u, 2u, 3u}) {
      CAPTURE(seed);
      const TSplineMap map = make_map(make_mesh(2, 40, seed));
      REQUIRE(map.mesh().num_hanging_vertices() > 0);
      const LoadedTSpline back = round_trip(map, square_meta(), scratch("adaptive"));
      CHECK(back.map.mesh().num_hanging_vertices() == map.mesh().num_hanging_vertices());
      CHECK(back.map.mesh().max_level() == map.mesh().max_level());
    }
  }

  TEST_CASE("awkward doubles and a missing boundary round trip") {
    const fs::path dir = scratch("doubles");
    TMesh mesh(1);
    mesh.build_topology();
    const tspline::TSplineBasis basis(mesh);
    const double special[] = {-0.0, 5e-324, 2.2250738585072014e-308, 1.0 / 3.0, 0.1, 1e300, -1.7976931348623157e308,
                              3.141592653589793, std::nextafter(1.0, 2.0), 123456789.123456789};
    std::vector<Eigen::Vector2d> cps;
    for (std::size_t a = 0; a < basis.size(); ++a) cps.emplace_back(special[a % 10], special[(a + 3) % 10]);
    const TSplineMap map(std::move(mesh), cps);
    TSplineFileMeta meta;
    meta.source = "";
    const fs::path p = dir / "t.json";
    write_tspline_file(p.string(), map, meta);
    const LoadedTSpline back = read_tspline_file(p.string());
    for (std::size_t a = 0; a < cps.size(); ++a) {
      CHECK(same_bits(back.map.control_points()[a].x(), cps[a].x()));
      CHECK(same_bits(back.map.control_points()[a].y(), cps[a].y()));
    }
    CHECK(back.meta.boundary.vertices.empty());
    CHECK(json::parse(slurp(p))["boundary"].is_null());
  }

  TEST_CASE("the file on disk has the documented fields") {
    const fs::path dir = scratch("fields");
    const TSplineMap map = make_map(make_mesh(2, 20, 5));
    write_tspline_file((dir / "t.json").string(), map, square_meta());
    const json doc = json::parse(slurp(dir / "t.json"));
    CHECK(doc["format"] == "tspline");
    CHECK(doc["version"] == 1);
    CHECK(doc["degree"] == 3);
    CHECK(doc["source"] == square_meta().source);
    CHECK(doc["parametric_domain"] == json::parse("[[0,0],[1,1]]"));
    CHECK(doc["normalization"].is_string());
    CHECK(doc["tmesh"]["root"] == TMesh::kRoot);
    REQUIRE(doc["tmesh"]["cells"].size() == map.mesh().num_cells());
    for (std::size_t c = 0; c < map.mesh().num_cells(); ++c) {
      const auto& q = map.mesh().node(map.mesh().cell_node(static_cast<int>(c)));
      CHECK(doc["tmesh"]["cells"][c] == json::array({q.level, q.i, q.j}));
    }
    REQUIRE(doc["functions"].size() == map.basis().size());
    std::map<std::string, std::size_t> kinds;
    for (std::size_t a = 0; a < map.basis().size(); ++a) {
      const json& f = doc["functions"][a];
      const auto& g = map.basis().function(static_cast<int>(a));
      ++kinds[f["kind"].get<std::string>()];
      const auto v = map.mesh().vertex_ipos(g.vertex);
      CHECK(f["vertex"] == json::array({v.x, v.y}));
      CHECK(f["knots_xi"].get<std::array<double, 5>>() == g.knots_xi);
      CHECK(f["knots_eta"].get<std::array<double, 5>>() == g.knots_eta);
      CHECK(f["interpolation_point"].size() == 2);
      CHECK(f["control_point"][0].get<double>() == map.control_points()[a].x());
    }
    CHECK(kinds["anchor"] == map.mesh().num_vertices());
    CHECK(kinds["corner"] == 4);
    CHECK(kinds.size() == 3);
    CHECK(doc["boundary"]["polygon"].size() == 5);
    CHECK(doc["boundary"]["file_index"] == json::array({4, 0, 1, 2, 3}));
    CHECK(doc["boundary"]["corners"] == json::array({0, 1, 2, 3}));
  }

  TEST_CASE("malformed files give InputError naming the JSON path") {
    const fs::path dir = scratch("malformed");
    const fs::path good = dir / "good.json";
    write_tspline_file(good.string(), make_map(make_mesh(2, 12, 9)), square_meta());
    const json doc = json::parse(slurp(good));
    // An interior anchor (no repeated knots), used for the knot cases.
    std::size_t interior = 0;
    for (std::size_t a = 0; a < doc["functions"].size(); ++a) {
      const auto k = doc["functions"][a]["knots_xi"].get<std::array<double, 5>>();
      const auto e = doc["functions"][a]["knots_eta"].get<std::array<double, 5>>();
      if (k[0] < k[1] && k[3] < k[4] && e[0] < e[1] && e[3] < e[4]) interior = a;
    }
    REQUIRE(interior > 0);
    const std::string fi = "/functions/" + std::to_string(interior);
    const fs::path bad = dir / "bad.json";
    auto expect_text = [&](const std::string& text, const std::string& needle) {
      spit(bad, text);
      const std::string msg = test_support::message_of<tspline::InputError>([&] { read_tspline_file(bad.string()); });
      CAPTURE(msg);
      CHECK(contains(msg, needle));
      CHECK(contains(msg, bad.string()));
    };
    auto expect = [&](const std::function<void(json&)>& edit, const std::string& needle) {
      json d = doc;
      edit(d);
      expect_text(d.dump(), needle);
    };
    expect_text("{\"format\": \"tspline\", ", "invalid JSON at byte");
    expect_text("", "invalid JSON at byte");
    expect_text("[1, 2]", "/: expected a JSON object");
    expect_text(std::string(slurp(good)).replace(slurp(good).find("\"control_point\": [") + 18, 0, "1e999, "),
                "invalid JSON");
    expect([](json& d) { d["format"] = "tspline-x"; }, "/format: expected \"tspline\"");
    expect([](json& d) { d["version"] = 99; }, "/version: unsupported version 99");
    expect([](json& d) { d["version"] = "1"; }, "/version: expected an integer");
    expect([](json& d) { d.erase("tmesh"); }, "/tmesh: missing field");
    expect([](json& d) { d["degree"] = 2; }, "/degree: only degree 3");
    expect([](json& d) { d["tmesh"]["root"] = 1024; }, "/tmesh/root: expected 1073741824");
    expect([](json& d) { d["functions"][3].erase("control_point"); }, "/functions/3/control_point: missing field");
    expect([](json& d) { d["functions"][12]["control_point"][1] = "NaN"; },
           "/functions/12/control_point: expected 2 finite numbers");
    expect([](json& d) { d["functions"][12]["control_point"][0] = nullptr; },  // how nlohmann writes NaN
           "/functions/12/control_point: expected 2 finite numbers");
    expect([](json& d) { d["functions"][2]["control_point"] = json::array({1.0}); },
           "/functions/2/control_point: expected 2 finite numbers");
    expect([](json& d) { d["functions"][5]["knots_eta"].erase(4); }, "/functions/5/knots_eta: expected 5 finite numbers");
    expect([&](json& d) { d["functions"][interior]["knots_xi"][3] = d["functions"][interior]["knots_xi"][4]; },
           fi + "/knots_xi: knot vector");
    expect([&](json& d) { d["functions"][interior]["knots_eta"][0] = 0.001; }, fi + "/knots_eta: knot vector");
    expect([&](json& d) { d["functions"][interior]["kind"] = "corner"; }, fi + ": the T-mesh has no corner function");
    expect([&](json& d) { d["functions"][interior]["kind"] = "cubic"; }, fi + "/kind: expected \"anchor\"");
    expect([&](json& d) { d["functions"][interior]["vertex"][0] = 0.5; }, fi + "/vertex/0: expected an integer");
    expect([&](json& d) { d["functions"][interior]["interpolation_point"][0] = 0.123; },
           fi + "/interpolation_point: expected");
    expect([](json& d) { d["functions"].push_back(d["functions"][0]); }, ": duplicates /functions/0");
    expect([](json& d) { d["functions"].erase(7); }, "/functions: missing the");
    expect([](json& d) { d["tmesh"]["cells"].erase(3); }, "/tmesh/cells: the cells do not tile the unit square");
    expect([](json& d) { d["tmesh"]["cells"].push_back(d["tmesh"]["cells"][0]); }, ": duplicate of cell /tmesh/cells/0");
    expect([](json& d) { d["tmesh"]["cells"].push_back(json::array({0, 0, 0})); }, "overlaps the larger cell");
    expect([](json& d) { d["tmesh"]["cells"][0] = json::array({31, 0, 0}); }, "/tmesh/cells/0/0: integer 31 outside");
    expect([](json& d) { d["tmesh"]["cells"][0] = json::array({1, 2, 0}); }, "/tmesh/cells/0/1: integer 2 outside");
    expect([](json& d) { d["tmesh"]["cells"][0] = json::array({1, 0}); }, "/tmesh/cells/0: expected [level, i, j]");
    expect([](json& d) {
      // Level-1 cells in three quadrants, level 3 in the fourth: tiles, but 2:1 balance fails.
      json cells = json::array({{1, 1, 0}, {1, 0, 1}, {1, 1, 1}});
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) cells.push_back({3, i, j});
      d["tmesh"]["cells"] = cells;
    }, "/tmesh/cells: the cells are not 2:1 balanced");
    expect([](json& d) { d["boundary"]["corners"][2] = 5; }, "/boundary/corners/2: integer 5 outside");
    expect([](json& d) { d["boundary"]["polygon"][1] = json::array({1, "x"}); }, "/boundary/polygon/1: expected 2");
    expect([](json& d) { d["boundary"]["file_index"].erase(0); }, "/boundary/file_index: expected 5 indices");
    expect([](json& d) { d.erase("source"); }, "/source: missing field");
    // The unmodified document still reads (the edits above were the only problem).
    spit(bad, doc.dump());
    CHECK_NOTHROW(read_tspline_file(bad.string()));
  }

  TEST_CASE("an unreadable path gives IoError") {
    const fs::path dir = scratch("unreadable");
    CHECK_THROWS_AS(read_tspline_file((dir / "missing.json").string()), tspline::IoError);
    CHECK_THROWS_AS(read_tspline_file(dir.string()), tspline::IoError);
    CHECK_THROWS_AS(write_tspline_file((dir / "no" / "such" / "t.json").string(), make_map(uniform(0)), {}),
                    tspline::IoError);
  }

  TEST_CASE("app: eval prints the map's values, info prints the counts") {
    const fs::path dir = scratch("app_ok");
    const TSplineMap map = make_map(make_mesh(2, 25, 4));
    const fs::path file = dir / "t.json";
    write_tspline_file(file.string(), map, square_meta());
    const std::vector<Eigen::Vector2d> pts{{0, 0}, {1, 1}, {0.3, 0.7}, {0.123456789, 0.987654321}, {0.5, 0.25}};
    std::string args = "eval '" + file.string() + "'", expected, expected_d;
    for (const auto& uv : pts) {
      args += " --at " + g17(uv.x()) + " " + g17(uv.y());
      const auto d = map.derivatives(uv, 1);
      const std::string head = g17(uv.x()) + " " + g17(uv.y()) + " " + g17(d.x.x()) + " " + g17(d.x.y());
      expected += head + "\n";
      expected_d += head + " " + g17(d.J(0, 0)) + " " + g17(d.J(1, 0)) + " " + g17(d.J(0, 1)) + " " +
                    g17(d.J(1, 1)) + " " + g17(d.J.determinant()) + "\n";
      CHECK(map.point(uv) == d.x);
    }
    RunResult r = run_app(args, dir);
    CHECK(r.exit_code == 0);
    CHECK(r.err.empty());
    CHECK(r.out == expected);
    r = run_app(args + " --derivatives", dir);
    CHECK(r.exit_code == 0);
    CHECK(r.out == expected_d);

    r = run_app("info '" + file.string() + "'", dir);
    CHECK(r.exit_code == 0);
    CAPTURE(r.out);
    std::size_t by_kind[3] = {0, 0, 0};
    for (const auto& f : map.basis().functions()) ++by_kind[static_cast<int>(f.kind)];
    CHECK(contains(r.out, "format: tspline version 1"));
    CHECK(contains(r.out, "source: " + square_meta().source + "\n"));
    CHECK(contains(r.out, "cells: " + std::to_string(map.mesh().num_cells()) + "\n"));
    CHECK(contains(r.out, "vertices: " + std::to_string(map.mesh().num_vertices()) + "\n"));
    CHECK(contains(r.out, "hanging vertices: " + std::to_string(map.mesh().num_hanging_vertices()) + "\n"));
    CHECK(contains(r.out, "functions: " + std::to_string(map.basis().size()) + " (anchor " +
                              std::to_string(by_kind[0]) + ", edge " + std::to_string(by_kind[1]) + ", corner 4)"));
    CHECK(contains(r.out, "max level: " + std::to_string(map.mesh().max_level()) + "\n"));
    CHECK(contains(r.out, "boundary bounding box: [0.20000000000000001, 3.2999999999999998] x [-0.10000000000000001, 2.1000000000000001]"));
    CHECK(contains(r.out, "corner (0,0): polygon vertex 0 (file index 4)"));

    for (const char* sub : {"eval", "info"}) {
      r = run_app(std::string(sub) + " --help", dir);
      CHECK(r.exit_code == 0);
      CHECK(contains(r.out, "TSPLINE"));
    }
    r = run_app("eval --help", dir);
    CHECK(contains(r.out, "--at"));
    CHECK(contains(r.out, "--derivatives"));
  }

  TEST_CASE("app: bad points and bad files give one error line and exit 1 / 2") {
    const fs::path dir = scratch("app_bad");
    const fs::path file = dir / "t.json";
    write_tspline_file(file.string(), make_map(uniform(1)), square_meta());
    spit(dir / "bad.json", "{\"format\": \"tspline\", \"version\": 99}");
    const std::string f = "'" + file.string() + "'";
    using Case = test_support::BadInvocation;
    const std::vector<Case> cases{
        {"eval " + f + " --at 1.5 0.5", "outside the parametric domain", 1},
        {"eval " + f + " --at 0.5 -0.25", "", 1},
        {"eval " + f + " --at abc 0.5", "is not a finite number", 1},
        {"eval " + f + " --at 0.5 nan", "is not a finite number", 1},
        {"eval " + f + " --at 0.5 0.5x", "is not a finite number", 1},
        {"eval " + f + " --at 0.5", "", 1},
        {"eval " + f, "--at", 1},
        {"eval '" + (dir / "missing.json").string() + "' --at 0.5 0.5", "missing.json", 2},
        {"info '" + (dir / "missing.json").string() + "'", "missing.json", 2},
        {"info '" + (dir / "bad.json").string() + "'", "/version: unsupported version 99", 1},
        {"eval '" + (dir / "bad.json").string() + "' --at 0 0", "/version: unsupported version 99", 1},
    };
    for (const Case& c : cases) {
      const RunResult r = test_support::check_bad_invocation(c, dir);
      CAPTURE(c.args);
      CAPTURE(r.err);
      CHECK(r.err.rfind("tspline: error: ", 0) == 0);
      CHECK(r.out.empty());
    }
  }
}
