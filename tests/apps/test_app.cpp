// End-to-end runs of the `tspline` command: good runs and every bad-input case.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {

using RunResult = test_support::AppRun;
using test_support::count_lines;
using test_support::slurp;

// A fresh scratch directory per test case.
fs::path scratch(const std::string& name) { return test_support::scratch_dir("app_test", name); }

RunResult run(const std::string& args, const fs::path& dir) { return test_support::run_app(args, dir); }

fs::path write_file(const fs::path& dir, const std::string& name, const std::string& content) {
  const fs::path p = dir / name;
  std::ofstream(p) << content;
  return p;
}

std::string polygons(const std::string& name) { return test_support::polygon_file(name); }


bool dir_is_empty_or_missing(const fs::path& d) { return !fs::exists(d) || fs::is_empty(d); }

// Bad input: non-zero exit, exactly one error line naming the problem, no output files.
void expect_clean_failure(const std::string& args, const fs::path& dir, const std::string& needle,
                          int expected_code) {
  const RunResult r = run(args, dir);
  CAPTURE(args);
  CAPTURE(r.err);
  CHECK(r.exit_code == expected_code);
  CHECK(count_lines(r.err) == 1);
  CHECK(r.err.rfind("tspline: error: ", 0) == 0);
  CHECK(r.err.find(needle) != std::string::npos);
  CHECK(dir_is_empty_or_missing(dir / "out"));
}

const char* kSquare = "0 0\n1 0\n1 1\n0 1\n";

}  // namespace

TEST_SUITE("app") {
  TEST_CASE("param on the unit square writes every output and a consistent report") {
    const fs::path d = scratch("square");
    const RunResult r = run("param --layout single '" + polygons("square.txt") + "' --out '" + (d / "out").string() + "'", d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    for (const char* f : {"parametric_tmesh.vtu", "physical_tmesh.vtu", "boundary.vtu", "report.json"})
      CHECK(fs::exists(d / "out" / f));
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["counts"]["polygon_vertices"] == 16);
    CHECK(rep["optimized"]["inverted_cells"] == 0);
    CHECK(rep["coons"]["inverted_cells"] == 0);
    // The square maps onto itself: every triangle keeps its ideal shape.
    CHECK(rep["optimized"]["min_mean_ratio"].get<double>() == doctest::Approx(1.0).epsilon(1e-9));
    CHECK(rep["counts"]["cells"] == 64);  // default initial level 3, no boundary refinement needed
    // Whole-map figures, each labelled: the certified bounds and the 26 x 26
    // sample (the map is the identity up to round-off: all 1); the adaptive
    // loop's sample stays under its old key.
    const auto& wm = rep["jacobian"]["whole_map"];
    for (const char* q : {"mean_ratio", "scaled_jacobian"}) {
      CAPTURE(q);
      CHECK(wm[q]["certified_lower_bound"].get<double>() == doctest::Approx(1.0).epsilon(1e-9));
      CHECK(wm[q]["certified_lower_bound"].get<double>() <= wm[q]["sampled_min"].get<double>());
      CHECK(wm[q]["samples_per_element"] == 26 * 26);
    }
    CHECK(wm["min_mean_ratio"].get<double>() == doctest::Approx(1.0).epsilon(1e-9));
    CHECK(wm["points_per_element"] == 81);
    // The corners the boundary fixes: right angles, the sides' tangents of equal speed.
    CHECK(wm["boundary_corner"]["scaled_jacobian"].get<double>() == doctest::Approx(1.0).epsilon(1e-9));
    CHECK(wm["boundary_corner"]["mean_ratio"].get<double>() == doctest::Approx(1.0).epsilon(1e-9));
    CHECK(wm["boundary_corner"]["angle_degrees"].get<double>() == doctest::Approx(90.0).epsilon(1e-9));
    CHECK(r.out.find("; the boundary fixes the scaled Jacobian at 1 at a corner of 90.0 degrees") != std::string::npos);
    CHECK(r.out.find("whole map: J_r >= 1 certified (min 1 in a dense sample of 676 points per element), scaled "
                     "Jacobian >= 1 certified (sampled min 1)") != std::string::npos);
    for (const char* stage : {"boundary", "tmesh", "coons", "optimization", "total"})
      CHECK(rep["seconds"].contains(stage));
    // Progress lines for each stage.
    for (const char* stage : {"boundary:", "t-mesh:", "coons:", "optimization ("})
      CHECK(r.out.find(stage) != std::string::npos);
    // No temporary files left behind.
    for (const auto& e : fs::directory_iterator(d / "out")) CHECK(e.path().filename().string()[0] != '.');
  }

  TEST_CASE(
      "--vtu-compression: every .vtu file with the compression asked for, LZ4 by default; the map the same") {
    const fs::path d = scratch("vtu_compression");
    // (compressor attribute of the files, or "" for none; the option, "" for the default)
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"vtkLZ4DataCompressor", ""}, {"vtkZLibDataCompressor", "zlib"}, {"", "none"}};
    std::set<std::string> maps;
    for (const std::string layout : {"single", "quad"})
      for (const auto& [compressor, option] : cases) {
        CAPTURE(layout);
        CAPTURE(option);
        const fs::path out = d / (layout + "_" + option);
        const RunResult r =
            run("param --layout " + layout + " '" + polygons("square.txt") + "' --out '" + out.string() +
                    "'" + (option.empty() ? "" : " --vtu-compression " + option),
                d);
        CAPTURE(r.err);
        REQUIRE(r.exit_code == 0);
        int files = 0;
        for (const auto& e : fs::directory_iterator(out)) {
          if (e.path().extension() != ".vtu") continue;
          CAPTURE(e.path().filename().string());
          const std::string text = slurp(e.path());
          const std::string header = text.substr(0, text.find("<AppendedData"));
          CHECK(header.find("<AppendedData") == std::string::npos);
          if (compressor.empty())
            CHECK(header.find("compressor=") == std::string::npos);
          else
            CHECK(header.find("compressor=\"" + compressor + "\"") != std::string::npos);
          ++files;
        }
        CHECK(files >= 6);
        const auto rep = nlohmann::json::parse(slurp(out / "report.json"));
        CHECK(rep["options"]["vtu-compression"] == (option.empty() ? "lz4" : option));
        maps.insert(slurp(out / "tspline.json"));
      }
    CHECK(maps.size() == 2);  // one map per layout, whatever the files' compression
    const fs::path bad = scratch("vtu_compression_bad");
    expect_clean_failure("param '" + polygons("square.txt") + "' --out '" + (bad / "out").string() +
                             "' --vtu-compression gzip",
                         bad, "--vtu-compression: gzip not in {lz4,zlib,none}", 1);
  }

  TEST_CASE("an invalid final map: exit 3, one clear line, files written and saying so") {
    // The gear's interpolating map folds at reflex tooth roots; without the
    // control point repair and without adaptive rounds it stays invalid.
    const fs::path d = scratch("invalid_map");
    const RunResult r = run("param --layout single '" + polygons("gear.txt") + "' --no-control-point-optimization --max-adapt 0 --out '" +
                                (d / "out").string() + "'",
                            d);
    CHECK(r.exit_code == 3);
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.find("not valid") != std::string::npos);
    for (const char* f : {"tspline.json", "surface.vtu", "control_net.vtu", "adapt.pvd", "report.json"})
      CHECK(fs::exists(d / "out" / f));
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["valid"] == false);
    CHECK(rep["jacobian"]["nonpositive_det_points"].get<int>() > 0);
    CHECK(rep["tspline"]["control_points_optimized"] == false);
  }

  TEST_CASE("--help explains every option") {
    const fs::path d = scratch("help");
    const RunResult r = run("param --help", d);
    CHECK(r.exit_code == 0);
    for (const char* opt : {"--out", "--corners", "--corner-trials", "--tol", "--tol-rel", "--init-level", "--max-level",
                            "--max-sweeps", "--omega", "--sweep-tol", "--polygon", "--min-jacobian", "--max-adapt",
                            "--max-cells", "--samples", "--no-control-point-optimization", "--quiet"})
      CHECK(r.out.find(opt) != std::string::npos);
  }

  TEST_CASE("given corners are used and reported in file numbering") {
    const fs::path d = scratch("corners");
    const RunResult r =
        run("param --layout single '" + polygons("lshape_cw.txt") + "' --corners 7,15,31,39 --out '" + (d / "out").string() + "'", d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["corners"]["vertices"][0]["file_index"] == 7);
    std::set<int> got;
    for (const auto& c : rep["corners"]["vertices"]) got.insert(c["file_index"].get<int>());
    CHECK(got == std::set<int>{7, 15, 31, 39});
    CHECK(rep["optimized"]["inverted_cells"] == 0);
  }

  TEST_CASE("a sharp tip is cut off within the boundary tolerance by default, kept with --blunt-tips 0") {
    const fs::path d = scratch("tips");
    // An arrow: tip (20, 0) of 2 atan(1/20) = 5.72 degrees, vertex 2.
    const fs::path in = write_file(d, "arrow.txt", "-4 -1\n0 -1\n20 0\n0 1\n-4 1\n");
    const RunResult cut = run("param --layout single --init-level 1 '" + in.string() + "' --out '" + (d / "cut").string() + "'", d);
    CAPTURE(cut.err);
    REQUIRE(cut.exit_code == 0);
    CHECK(cut.out.find("note: the outer ring: blunted the tip at vertex 2 (5.72 degrees") != std::string::npos);
    const auto rep = nlohmann::json::parse(slurp(d / "cut" / "report.json"));
    REQUIRE(rep["input_cleaning"]["notes"].size() == 1);
    CHECK(rep["input_cleaning"]["notes"][0].get<std::string>().find("new corners 92.9 and 92.9 degrees") !=
          std::string::npos);
    CHECK(rep["counts"]["polygon_vertices"] == 6);  // the tip became two cut points
    const RunResult kept =
        run("param --layout single --init-level 1 '" + in.string() + "' --blunt-tips 0 --out '" + (d / "kept").string() + "'", d);
    REQUIRE(kept.exit_code == 0);
    CHECK(kept.out.find("blunted") == std::string::npos);
    CHECK(nlohmann::json::parse(slurp(d / "kept" / "report.json"))["counts"]["polygon_vertices"] == 5);
    const RunResult wrong = run("param '" + in.string() + "' --blunt-tips 95 --out '" + (d / "x").string() + "'", d);
    CHECK(wrong.exit_code == 1);
    CHECK(wrong.err.find("--blunt-tips") != std::string::npos);
    CHECK_FALSE(fs::exists(d / "x" / "report.json"));
  }

  TEST_CASE("real data is cleaned, not rejected: repeated vertices and zero-area spikes, with notes in file numbering") {
    const fs::path d = scratch("cleaning");
    // A 4 x 4 square (CW in the file) with a repeated vertex (2 = 1) and a spike
    // 5 -> 6 -> 7 that doubles back along the top edge: vertices 2 and 6 go.
    const fs::path in = write_file(d, "spiky.txt",
                                   "0 0\n0 4\n0 4\n2 4\n3 4\n3.5 4\n4.5 4\n4 4\n4 0\n");
    const RunResult r = run("param --layout single '" + in.string() + "' --corners 0,1,7,8 --out '" + (d / "out").string() + "'", d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    // One note for the ring, naming each removed vertex.
    CHECK(r.out.find("note: the boundary: removed vertex 2 (repeats vertex 1); removed vertex 6 (tip of a zero-area "
                     "spike: edges 5-6 and 6-7 overlap)") != std::string::npos);
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["input_cleaning"]["removed_vertices"] == nlohmann::json::array({2, 6}));
    CHECK(rep["counts"]["polygon_vertices"] == 7);
    std::set<int> got;
    for (const auto& c : rep["corners"]["vertices"]) got.insert(c["file_index"].get<int>());
    CHECK(got == std::set<int>{0, 1, 7, 8});
    CHECK(rep["certified_valid"] == true);
  }

  TEST_CASE("bad input: each case one clear error line, non-zero exit, no output") {
    const fs::path d = scratch("bad");
    const std::string out = " --out '" + (d / "out").string() + "'";
    auto param = [&](const fs::path& in, const std::string& extra = "") {
      return "param --layout single '" + in.string() + "'" + out + extra;
    };
    SUBCASE("empty file") { expect_clean_failure(param(write_file(d, "e.txt", "")), d, "empty", 1); }
    SUBCASE("only comments") {
      expect_clean_failure(param(write_file(d, "c.txt", "# nothing\n\n# here\n")), d, "empty", 1);
    }
    SUBCASE("three vertices") {
      expect_clean_failure(param(write_file(d, "t.txt", "0 0\n1 0\n0 1\n")), d, "3 vertices", 1);
    }
    SUBCASE("NaN coordinate") {
      expect_clean_failure(param(write_file(d, "n.txt", "0 0\n1 0\nnan 1\n0 1\n")), d, "not finite", 1);
    }
    SUBCASE("non-numeric line") {
      expect_clean_failure(param(write_file(d, "x.txt", "0 0\n1 0\nhello world\n0 1\n")), d, ":3:", 1);
    }
    SUBCASE("a corner given on a vertex that the cleaning removed") {
      expect_clean_failure(param(write_file(d, "r.txt", "0 0\n1 0\n1 0\n1 1\n0 1\n"), " --corners 0,2,3,4"), d,
                           "2", 1);
    }
    SUBCASE("self-intersecting polygon names the crossing edges") {
      expect_clean_failure(param(write_file(d, "s.txt", "0 0\n1 1\n1 0\n0 1\n")), d, "0-1", 1);
    }
    SUBCASE("zero area") {
      expect_clean_failure(param(write_file(d, "z.txt", "0 0\n1 0\n2 0\n3 0\n")), d, "area", 1);
    }
    SUBCASE("corner index out of range") {
      expect_clean_failure(param(write_file(d, "q.txt", kSquare), " --corners 0,1,2,4"), d, "4", 1);
    }
    SUBCASE("repeated corner index") {
      expect_clean_failure(param(write_file(d, "q.txt", kSquare), " --corners 0,1,1,3"), d, "1", 1);
    }
    SUBCASE("corners not in cyclic order") {
      expect_clean_failure(param(write_file(d, "q.txt", kSquare), " --corners 0,2,1,3"), d, "cyclic", 1);
    }
    SUBCASE("corner on a straight part of the boundary") {
      expect_clean_failure(param(polygons("lshape_cw.txt"), " --corners 3,9,21,33"), d, "convex", 1);
    }
    SUBCASE("malformed --corners") {
      expect_clean_failure(param(write_file(d, "q.txt", kSquare), " --corners 0,1,x,3"), d, "x", 1);
    }
    SUBCASE("unreadable input path") {
      expect_clean_failure(param(d / "does_not_exist.txt"), d, "does_not_exist.txt", 2);
    }
    SUBCASE("input path is a directory") { expect_clean_failure(param(d), d, d.string(), 2); }
    SUBCASE("unwritable output path") {
      const fs::path blocker = write_file(d, "blocker", "x");
      const std::string args =
          "param --layout single '" + write_file(d, "q.txt", kSquare).string() + "' --out '" + (blocker / "sub").string() + "'";
      expect_clean_failure(args, d, "blocker", 2);
    }
    SUBCASE("negative tolerance") {
      expect_clean_failure(param(write_file(d, "q.txt", kSquare), " --tol -1"), d, "--tol", 1);
    }
    SUBCASE("missing --out") {
      const RunResult r = run("param --layout single '" + write_file(d, "q.txt", kSquare).string() + "'", d);
      CHECK(r.exit_code == 1);
      CHECK(count_lines(r.err) == 1);
      CHECK(r.err.find("--out") != std::string::npos);
    }
  }
}
