// The examples in examples/ run and their results are right: each example
// checks itself (exit 0 only if right), and here we also read what it printed.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "test_support.h"

namespace fs = std::filesystem;
using test_support::contains;
using test_support::require_success;
using test_support::run_program;

namespace {

fs::path scratch(const std::string& name) { return test_support::scratch_dir("examples", name); }
std::string q(const fs::path& p) { return test_support::quoted(p); }

/// The number after "key " on the line that starts with key.
double value_after(const std::string& out, const std::string& key) {
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + " ", 0) == 0) return std::stod(line.substr(key.size() + 1));
  FAIL("no line '" << key << " ...' in:\n" << out);
  return 0.0;
}

/// Example 1 on the flower, run once per process (examples 3 and 4 read its
/// tspline.json); the checks of what it printed are the "ex1" case's own.
struct Example1 {
  test_support::AppRun run;
  fs::path tspline_json;
};
const Example1& example1() {
  static const Example1 ex = [] {
    const fs::path d = scratch("ex1");
    return Example1{run_program(EXAMPLE_PARAMETERIZE, q(test_support::polygon_file("flower.txt")) + " " + q(d / "out"), d),
                    d / "out" / "tspline.json"};
  }();
  return ex;
}

/// tspline.json written by example 1 (fails the calling case if example 1 failed).
fs::path example1_output() {
  CAPTURE(example1().run.err);
  REQUIRE(example1().run.exit_code == 0);
  return example1().tspline_json;
}

}  // namespace

TEST_SUITE("examples") {
  TEST_CASE("ex1: parameterize a polygon") {
    const test_support::AppRun r = require_success(example1().run);
    CHECK(value_after(r.out, "valid") == 1.0);
    CHECK(value_after(r.out, "certified") == 1.0);
    // The steps by hand: the Coons start of the flower folds at its petals and
    // the K* optimization (step 7) unfolds every cell.
    CHECK(value_after(r.out, "coons_inverted") > 0.0);
    CHECK(value_after(r.out, "optimized_inverted") == 0.0);
    // Good at the Gauss points (delta = 0.2); over the whole map the minimum is
    // positive (certified) and never above the Gauss points' one.
    CHECK(value_after(r.out, "min_jr_gauss") >= 0.2);
    CHECK(value_after(r.out, "min_jr_whole_map") > 0.0);
    CHECK(value_after(r.out, "min_jr_whole_map") <= value_after(r.out, "min_jr_gauss"));
    CHECK(value_after(r.out, "min_jr_certified") > 0.0);
    CHECK(value_after(r.out, "min_jr_certified") <= value_after(r.out, "min_jr_whole_map"));
    CHECK(value_after(r.out, "min_jr_gauss") <= value_after(r.out, "mean_jr"));
    CHECK(value_after(r.out, "cells") > 100);
    CHECK(value_after(r.out, "functions") > value_after(r.out, "cells"));
    // The files `tspline param` writes, the map readable by `tspline info`.
    const fs::path out = example1().tspline_json.parent_path();
    for (const char* f : {"tspline.json", "surface.vtu", "control_net.vtu", "report.json"}) {
      CAPTURE(f);
      CHECK(fs::exists(out / f));
    }
    const auto info = test_support::run_app("info " + q(out / "tspline.json"), out);
    CHECK(info.exit_code == 0);
    CHECK(contains(info.out, "cells: " + std::to_string(static_cast<long>(value_after(r.out, "cells")))));
  }

  TEST_CASE("ex2: corners and tolerance") {
    const fs::path d = scratch("ex2");
    const auto r = require_success(run_program(EXAMPLE_CORNERS_TOLERANCE, "", d));
    // One line per tolerance; the cell count grows as the tolerance shrinks and
    // the chosen corners are the images of the square's corners.
    std::istringstream in(r.out);
    std::string line;
    std::vector<double> cells;
    while (std::getline(in, line))
      if (line.rfind("tol ", 0) == 0) {
        std::istringstream l(line);
        std::string w;
        double tol, c, err;
        l >> w >> tol >> w >> c >> w >> err;
        cells.push_back(c);
        CHECK(err <= 1e-12);
        CHECK(contains(line, "valid 1"));
      }
    REQUIRE(cells.size() == 3);
    CHECK(cells[0] < cells[1]);
    CHECK(cells[1] < cells[2]);
  }

  TEST_CASE("ex3: read back and evaluate") {
    const fs::path d = scratch("ex3");
    const auto r = require_success(run_program(EXAMPLE_EVALUATE, q(example1_output()), d));
    CHECK(value_after(r.out, "det J =") > 0.0);
    const double jr = value_after(r.out, "J_r =");
    CHECK(jr > 0.0);
    CHECK(jr <= 1.0);
    // Bad input: a clear message and exit 2.
    const auto bad = run_program(EXAMPLE_EVALUATE, q(d / "nonesuch.json"), d);
    CHECK(bad.exit_code == 2);
    CHECK(contains(bad.err, "nonesuch.json"));
  }

  TEST_CASE("ex4: adaptive Poisson with user f and g") {
    const fs::path d = scratch("ex4");
    const auto r = require_success(run_program(EXAMPLE_POISSON, q(example1_output()), d));
    CHECK(value_after(r.out, "H1 error reduced by") >= 2.0);
  }

  TEST_CASE("ex5: untangle a planar mesh") {
    const fs::path d = scratch("ex5");
    const auto r = require_success(run_program(EXAMPLE_UNTANGLE, "", d));
    CHECK(value_after(r.out, "before: inverted") > 10);
    CHECK(value_after(r.out, "after: inverted") == 0.0);
  }

  TEST_CASE("ex7: a moving boundary re-parameterized from the previous map") {
    const fs::path d = scratch("ex7");
    const std::string coast = std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/puerto_rico.txt";
    // It draws with Cairo: fontconfig's caches live to the end of the process
    // (not a leak of ours), suppressed for LeakSanitizer in the sanitizer build.
    const std::string supp = std::string(TSPLINE_TEST_DATA_DIR) + "/../support/lsan_cairo.supp";
    // The example checks that every step is certified and at least half as good as the cold start.
    const auto r = require_success(run_program("/usr/bin/env",
                                               q("LSAN_OPTIONS=suppressions=" + supp + ":print_suppressions=0") +
                                                   " " + q(EXAMPLE_MOVING_BOUNDARY) + " " + q(coast) + " " +
                                                   q(d / "out"),
                                               d));
    CHECK(contains(r.out, "  20 "));
    CHECK(contains(r.out, "of 20 steps kept the T-mesh"));
    CHECK(!contains(r.out, " NO "));
    for (const char* png : {"first.png", "last.png"}) {
      CAPTURE(png);
      CHECK(fs::file_size(d / "out" / png) > 10000);
    }
  }
}
