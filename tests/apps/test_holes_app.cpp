// End-to-end runs of `tspline param`, `check`, `eval` and `info` on domains
// with holes, and every bad-input case of holes and cuts.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_support.h"
#include "toolkit/io/vtu_reader.h"

namespace fs = std::filesystem;

namespace {

using test_support::contains;
using test_support::count_lines;
using test_support::quoted;

fs::path scratch(const std::string& name) { return test_support::scratch_dir("holes_app", name); }

fs::path write_file(const fs::path& dir, const std::string& name, const std::string& content) {
  const fs::path p = dir / name;
  std::ofstream(p) << content;
  return p;
}

std::string holes_file(const std::string& name) { return std::string(TSPLINE_TEST_DATA_DIR) + "/holes/" + name; }

// Bad input: exit 1, one error line naming the problem, no output files.
void expect_input_error(const std::string& args, const fs::path& dir, const std::string& needle) {
  const test_support::AppRun r = test_support::run_app(args, dir);
  CAPTURE(args);
  CAPTURE(r.err);
  CHECK(r.exit_code == 1);
  CHECK(count_lines(r.err) == 1);
  CHECK(r.err.rfind("tspline: error: ", 0) == 0);
  CHECK(contains(r.err, needle));
  CHECK((!fs::exists(dir / "out") || fs::is_empty(dir / "out")));
}

const char* kFrame = "0 0\n10 0\n10 10\n0 10\n\n";

}  // namespace

TEST_SUITE("holes_app") {
  TEST_CASE("param on the plate with a hole writes a certified multi-patch map that check, eval and info read") {
    const fs::path d = scratch("plate");
    const fs::path out = d / "out";
    const auto r = test_support::run_app("param " + quoted(fs::path(holes_file("plate_with_hole.txt"))) + " --out " + quoted(out), d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json file = nlohmann::json::parse(test_support::slurp(out / "tspline.json"));
    const std::size_t patches = file["patches"].size();
    CHECK(contains(r.out, std::to_string(patches) + " patches"));
    CHECK(file["version"] == 2);
    CHECK(patches >= 4);
    CHECK(file["patches"][0]["version"] == 1);  // each patch a complete version-1 document
    const nlohmann::json rep = nlohmann::json::parse(test_support::slurp(out / "report.json"));
    CHECK(rep["totals"]["certified_valid"] == true);
    CHECK(rep["totals"]["area_relative_error"].get<double>() < 1e-3);
    CHECK(rep["totals"]["max_interface_gap_relative"].get<double>() <= 1e-12);
    CHECK(rep["patches"].size() == patches);
    // Whole-map quality over all patches: the smallest certified bound and sample of the patches.
    for (const char* q : {"mean_ratio", "scaled_jacobian"}) {
      CAPTURE(q);
      const auto& t = rep["totals"]["whole_map"][q];
      double lowest = 2.0, sampled = 2.0;
      for (const auto& p : rep["patches"]) {
        lowest = std::min(lowest, p["jacobian"]["whole_map"][q]["certified_lower_bound"].get<double>());
        sampled = std::min(sampled, p["jacobian"]["whole_map"][q]["sampled_min"].get<double>());
      }
      CHECK(t["certified_lower_bound"].get<double>() == lowest);
      CHECK(t["sampled_min"].get<double>() == sampled);
      CHECK(t["certified_lower_bound"].get<double>() > 0.0);
      CHECK(t["certified_lower_bound"].get<double>() <= sampled);
      CHECK(t["certified_lower_bound_patch"].get<std::size_t>() < patches);
      // ... also where a single-patch report has it, so readers need no case for several patches.
      CHECK(rep["jacobian"]["whole_map"][q] == t);
    }
    // Every corner of the square has a cut ending there (its diagonals), so no
    // patch corner has both sides on the rings: nothing for the boundary to fix.
    CHECK_FALSE(rep["totals"]["whole_map"].contains("boundary_corner"));
    CHECK(rep["certified_valid"] == true);
    double dense = 2.0;
    for (const auto& p : rep["patches"]) dense = std::min(dense, p["jacobian"]["whole_map"]["min_mean_ratio"].get<double>());
    CHECK(rep["jacobian"]["whole_map"]["min_mean_ratio"].get<double>() == dense);
    CHECK(contains(r.out, "whole map: J_r >= "));
    // The surface covers every patch: cell data `patch` in 0..3.
    const std::string vtu = test_support::slurp(out / "surface.vtu");
    CHECK(contains(vtu, "Name=\"patch\""));

    const auto check = test_support::run_app("check " + quoted(out / "tspline.json"), d);
    CHECK(check.exit_code == 0);
    CHECK(contains(check.out, "result: every patch certified valid"));
    // check recomputes the certified whole-map bounds from the file: the
    // report's (made from the map in memory) to the 6 digits it prints; the
    // worst patch listed first is the report's patch of the J_r bound.
    {
      auto printed = [&](const std::string& key) {
        const std::size_t at = check.out.find(key);
        REQUIRE(at != std::string::npos);
        return std::stod(check.out.substr(at + key.size()));
      };
      const auto& w = rep["totals"]["whole_map"];
      for (const auto& [key, q] : {std::pair<std::string, const char*>{"whole map: J_r >= ", "mean_ratio"},
                                   {"whole map: scaled Jacobian >= ", "scaled_jacobian"}}) {
        CAPTURE(key);
        const double bound = w[q]["certified_lower_bound"].get<double>();
        CHECK(printed(key) == doctest::Approx(bound).epsilon(1e-5));
      }
      CHECK(printed("bezier elements: ") == rep["totals"]["bezier_elements"].get<double>());
      CHECK(contains(check.out, "certified: " + std::to_string(rep["totals"]["bezier_elements"].get<std::size_t>()) +
                                    " of " + std::to_string(rep["totals"]["bezier_elements"].get<std::size_t>()) +
                                    " elements, " + std::to_string(patches) + " of " + std::to_string(patches) +
                                    " patches"));
      CHECK(printed("worst patches (by the certified J_r bound):\n  patch ") ==
            w["mean_ratio"]["certified_lower_bound_patch"].get<double>());
    }
    const auto info = test_support::run_app("info " + quoted(out / "tspline.json"), d);
    CHECK(info.exit_code == 0);
    CHECK(contains(info.out, "format: tspline version 2"));
    CHECK(contains(info.out, "patches: " + std::to_string(patches)));
    // The totals over every patch are the report's; --per-patch adds each patch's block.
    CHECK(contains(info.out, "cells: " + std::to_string(rep["totals"]["cells"].get<std::size_t>()) + " (per patch "));
    CHECK(contains(info.out, "functions: " + std::to_string(rep["totals"]["functions"].get<std::size_t>()) + " ("));
    CHECK_FALSE(contains(info.out, "patch 0:"));
    const auto info_all = test_support::run_app("info " + quoted(out / "tspline.json") + " --per-patch", d);
    CHECK(info_all.exit_code == 0);
    CHECK(contains(info_all.out, "patch " + std::to_string(patches - 1) + ":\ncells: "));
    CHECK(contains(info_all.out, "interface along cut 0: "));
    const auto eval = test_support::run_app("eval " + quoted(out / "tspline.json") + " --patch 3 --at 0 0", d);
    CHECK(eval.exit_code == 0);
    const auto no_patch = test_support::run_app("eval " + quoted(out / "tspline.json") + " --at 0 0", d);
    CHECK(no_patch.exit_code == 1);
    CHECK(contains(no_patch.err, "give --patch P"));

    // Bezier export: one document per patch, 416 elements in all as in the report.
    const auto bez = test_support::run_app(
        "export " + quoted(out / "tspline.json") + " -q --bezier " + quoted(d / "bezier.json"), d);
    REQUIRE(bez.exit_code == 0);
    const nlohmann::json bdoc = nlohmann::json::parse(test_support::slurp(d / "bezier.json"));
    std::size_t elements = 0;
    for (const auto& p : bdoc["patches"]) elements += p["elements"].size();
    CHECK(elements == rep["totals"]["bezier_elements"].get<std::size_t>());
    CHECK(bdoc["interfaces"].size() == file["interfaces"].size());

    // Poisson with C0 coupling, uniform refinement: the solution is continuous across the cuts.
    const auto pois = test_support::run_app("poisson " + quoted(out / "tspline.json") +
                                                " --problem sinsin --refine uniform --steps 2 -q --out " +
                                                quoted(d / "poisson"),
                                            d);
    CAPTURE(pois.err);
    REQUIRE(pois.exit_code == 0);
    const nlohmann::json prep = nlohmann::json::parse(test_support::slurp(d / "poisson" / "report.json"));
    REQUIRE(prep["steps"].size() == 2);
    CHECK(prep["steps"][1]["max_interface_jump"].get<double>() < 1e-12);
    CHECK(prep["steps"][1]["l2"].get<double>() < prep["steps"][0]["l2"].get<double>() / 8);
    // The solution of every patch per step (solution/step_NNN.vtu, solution.pvd), so
    // that `render --view solution` draws it: u_h - u there is within the step's error.
    const toolkit::io::VtuMesh sol = toolkit::io::read_vtu((d / "poisson" / "solution" / "step_001.vtu").string());
    CHECK(fs::exists(d / "poisson" / "solution.pvd"));
    double worst = 0.0, max_patch = 0.0;
    for (double e : sol.point_scalars.at("error")) worst = std::max(worst, std::abs(e));
    for (double q : sol.cell_scalars.at("patch")) max_patch = std::max(max_patch, q);
    CHECK(max_patch == static_cast<double>(patches - 1));
    CHECK(worst > 0.0);
    CHECK(worst < 0.05);
    const auto pic = test_support::run_app(
        "render " + quoted(d / "poisson") + " --view solution -q --png " + quoted(d / "solution.png"), d);
    CAPTURE(pic.err);
    CHECK(pic.exit_code == 0);
    CHECK(fs::file_size(d / "solution.png") > 1000);
    for (const char* view : {"tmesh", "jacobian", "control-net"}) {
      const auto v = test_support::run_app("render " + quoted(out) + " --view " + view + " -q --png " +
                                               quoted(d / (std::string(view) + ".png")),
                                           d);
      CHECK(v.exit_code == 0);
    }
    // Gmsh export of every patch (conforming across the cuts: msh_export tests).
    const auto msh = test_support::run_app(
        "export " + quoted(out / "tspline.json") + " --msh " + quoted(d / "plate.msh"), d);
    CAPTURE(msh.err);
    REQUIRE(msh.exit_code == 0);
    CHECK(contains(msh.out, "on " + std::to_string(patches) + " patches"));
    CHECK(contains(test_support::slurp(d / "plate.msh"), "\"patch " + std::to_string(patches - 1) + "\""));
    const auto adaptive = test_support::run_app(
        "poisson " + quoted(out / "tspline.json") + " --problem gaussian --steps 3 -q --out " + quoted(d / "p2"), d);
    CAPTURE(adaptive.err);
    REQUIRE(adaptive.exit_code == 0);
    const nlohmann::json arep = nlohmann::json::parse(test_support::slurp(d / "p2" / "report.json"));
    REQUIRE(arep["steps"].size() == 3);
    CHECK(arep["steps"][2]["h1"].get<double>() < arep["steps"][0]["h1"].get<double>());
    CHECK(arep["steps"][2]["max_interface_jump"].get<double>() < 1e-12);
  }

  TEST_CASE("a domain without holes keeps format version 1") {
    const fs::path d = scratch("square");
    const fs::path in = write_file(d, "square.txt", "0 0\n1 0\n1 1\n0 1\n");
    const auto r = test_support::run_app("param " + quoted(in) + " --out " + quoted(d / "out") + " -q", d);
    REQUIRE(r.exit_code == 0);
    CHECK(nlohmann::json::parse(test_support::slurp(d / "out" / "tspline.json"))["version"] == 1);
  }

  TEST_CASE("bad holes and bad cuts: exit 1 with the rings, edges or cuts named") {
    const fs::path d = scratch("bad");
    auto param = [&](const fs::path& in, const std::string& extra = "") {
      return "param " + quoted(in) + " --out " + quoted(d / "out") + extra;
    };
    expect_input_error(param(write_file(d, "crossing.txt", std::string(kFrame) + "1 1\n4 1\n4 4\n1 4\n\n3 3\n6 3\n6 6\n3 6\n")),
                       d, "hole 2 crosses hole 1: edge");
    expect_input_error(param(write_file(d, "touching.txt", std::string(kFrame) + "5 0\n6 2\n5 3\n4 2\n")), d,
                       "hole 1 touches the outer ring");
    expect_input_error(param(write_file(d, "outside.txt", std::string(kFrame) + "20 20\n21 20\n21 21\n20 21\n")), d,
                       "hole 1 lies outside the outer ring");
    const fs::path framed = write_file(d, "framed.txt", std::string(kFrame) + "3 3\n7 3\n7 7\n3 7\n");
    expect_input_error(param(framed, " --cuts " + quoted(write_file(d, "x.txt", "3 3\n5 0\n\n5 3\n3 0\n"))), d,
                       "cuts 1 and 2 cross");
    expect_input_error(param(framed, " --cuts " + quoted(write_file(d, "off.txt", "3 3\n1 1\n"))), d,
                       "lies neither on a ring nor at an end of another cut");
    expect_input_error(param(framed, " --cuts " + quoted(write_file(d, "one.txt", "3 3\n0 0\n"))), d,
                       "not simply connected");
  }

  TEST_CASE("a bow-tie hole: an input error by default, its convex hull with --repair-crossings") {
    const fs::path d = scratch("bowtie");
    // Hole 1 crosses itself (edges 1-2 and 3-0 cross at (5, 5)): two triangles of area 1 each.
    const fs::path in = write_file(d, "bowtie.txt", std::string(kFrame) + "4 4\n6 4\n4 6\n6 6\n");
    expect_input_error("param " + quoted(in) + " --out " + quoted(d / "out"), d,
                       "Hole 1: polygon is not simple: edges 1-2 and 3-0 intersect");
    const fs::path out = d / "fixed";
    const auto r =
        test_support::run_app("param " + quoted(in) + " --out " + quoted(out) + " --repair-crossings --init-level 1", d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(contains(r.out + r.err, "hole 1: crosses itself; replaced by its convex hull"));
    const nlohmann::json rep = nlohmann::json::parse(test_support::slurp(out / "report.json"));
    REQUIRE(rep["input_cleaning"]["notes"].size() == 1);
    CHECK(contains(rep["input_cleaning"]["notes"][0].get<std::string>(), "area 0 (signed, lobes cancelling) -> 4"));
    // The map covers the frame less the hull, the square [4, 6]^2.
    CHECK(rep["totals"]["certified_valid"] == true);
    CHECK(rep["totals"]["domain_area"].get<double>() == doctest::Approx(100.0 - 4.0));
  }

  TEST_CASE("given cuts: a framed square cut along its diagonals is four certified trapezoids") {
    const fs::path d = scratch("given");
    const fs::path framed = write_file(d, "framed.txt", std::string(kFrame) + "3 3\n7 3\n7 7\n3 7\n");
    const fs::path cuts = write_file(d, "cuts.txt", "3 3\n0 0\n\n7 3\n10 0\n\n7 7\n10 10\n\n3 7\n0 10\n");
    const auto r = test_support::run_app(
        "param " + quoted(framed) + " --cuts " + quoted(cuts) + " --out " + quoted(d / "out") + " -q", d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json rep = nlohmann::json::parse(test_support::slurp(d / "out" / "report.json"));
    CHECK(rep["patches_count"] == 4);
    CHECK(rep["cuts"]["choice"] == "given");
    CHECK(rep["totals"]["domain_area"].get<double>() == doctest::Approx(84));
    // Straight-sided patches: the map reproduces the area to round-off.
    CHECK(rep["totals"]["map_area"].get<double>() == doctest::Approx(84).epsilon(1e-9));
    CHECK(rep["totals"]["certified_valid"] == true);
  }
}
