// Bad input as a new user, or a mutation fuzzer, gives it: every
// case ends with exit 0-3 and one clear line, never a signal, an internal
// error or a silent hang; Ctrl-C stops a long run without half-written files.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_support.h"
#include "tspline/boundary/corners.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/parameterization.h"
#include "tspline/boundary/polygon_validation.h"

extern char** environ;

namespace fs = std::filesystem;
using test_support::contains;
using test_support::count_lines;
using test_support::quoted;

namespace {

fs::path scratch(const std::string& name) { return test_support::scratch_dir("hardening", name); }

std::string coastline(const std::string& name) {
  std::string path = TSPLINE_TEST_DATA_DIR;  // (as test_support::polygon_file)
  return path.append("/coastlines/").append(name);
}

/// The polygon file `src` with its k-th vertex (0-based, comments skipped)
/// given the coordinate `value` in `axis` (0: x, 1: y), written to `dst`.
fs::path move_vertex(const std::string& src, std::size_t k, int axis, const std::string& value, const fs::path& dst) {
  std::ifstream in(src);
  std::ofstream out(dst);
  std::string line;
  std::size_t n = 0;
  bool moved = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') {
      out << line << '\n';
      continue;
    }
    if (n++ == k) {
      std::istringstream s(line);
      std::string x, y;
      s >> x >> y;
      (axis == 0 ? x : y) = value;
      line = x + " " + y;
      moved = true;
    }
    out << line << '\n';
  }
  REQUIRE(moved);
  return dst;
}

/// Every vertex of the polygon file scaled by `s` (written with 17 digits).
fs::path scaled(const std::string& src, double s, const fs::path& dst) {
  std::ifstream in(src);
  std::ofstream out(dst);
  out.precision(17);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream l(line);
    double x, y;
    l >> x >> y;
    out << x * s << ' ' << y * s << '\n';
  }
  return dst;
}

/// `tspline param IN --out DIR/out EXTRA`: the exit code is one of 0..3 and,
/// unless it is 0, stderr is one line that starts with "tspline: error: ".
test_support::AppRun param(const fs::path& in, const fs::path& d, const std::string& extra = "") {
  const auto r = test_support::run_app("param --layout single " + quoted(in) + " --out " + quoted(d / "out") + " -q " + extra, d);
  CAPTURE(in);
  CAPTURE(extra);
  CAPTURE(r.err);
  CHECK(r.exit_code >= 0);
  CHECK(r.exit_code <= 3);
  if (r.exit_code != 0) {
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.rfind("tspline: error: ", 0) == 0);
  }
  return r;
}

}  // namespace

TEST_SUITE("hardening") {
  TEST_CASE("degenerate scales are rejected (not rescaled) with one line naming the scale") {
    const fs::path d = scratch("scales");
    const std::string square = test_support::polygon_file("square.txt");
    // Corners at 1e300: lengths squared overflow (this was a segfault).
    const auto big = param(scaled(square, 1e300, d / "big.txt"), d);
    CHECK(big.exit_code == 1);
    CHECK(contains(big.err, "too far from the origin"));
    CHECK(contains(big.err, "1e+50"));
    CHECK(!fs::exists(d / "out" / "tspline.json"));
    // Corners at 1e-300: areas underflow (this was a wrong "inner angle of 0 degrees").
    const auto tiny = param(scaled(square, 1e-300, d / "tiny.txt"), d);
    CHECK(tiny.exit_code == 1);
    CHECK(contains(tiny.err, "too small"));
    CHECK(contains(tiny.err, "1e-50"));
    // Inside the supported range the same square is parameterized.
    for (double s : {1e40, 1e-40}) {
      CAPTURE(s);
      const fs::path ds = scratch("scale_ok");
      const auto ok = param(scaled(square, s, ds / "sq.txt"), ds, "--init-level 2 --max-adapt 0");
      CHECK(ok.exit_code == 0);
      CHECK(fs::exists(ds / "out" / "tspline.json"));
    }
    // The library says the same to every caller.
    const tspline::Polygon p = test_support::make_polygon({{0, 0}, {2e50, 0}, {2e50, 1}, {0, 1}});
    CHECK(contains(test_support::message_of<tspline::InputError>([&] { tspline::validate_polygon(p); }),
                   "vertex 1"));
  }

  TEST_CASE("a coastline vertex moved to y = 2^32 + 1 or -(2^31 + 1): a clear error, no signal") {
    const fs::path d = scratch("coast_y");
    const std::string isle = coastline("isle_of_man.txt");
    // 2^32 + 1 km: a spike 4e9 km long, so thin against the island that no
    // map is valid (this was a segfault: the automatic corners indexed an empty
    // candidate list). The run finishes in seconds and says why.
    const auto up = param(move_vertex(isle, 19, 1, "4294967297", d / "up.txt"), d);
    CHECK(up.exit_code == 3);
    CHECK(contains(up.err, "the map is not valid"));
    // -(2^31 + 1): the spike crosses the island.
    const auto down = param(move_vertex(isle, 19, 1, "-2147483649", d / "down.txt"), d);
    CHECK(down.exit_code == 1);
    CHECK(contains(down.err, "not simple"));
  }

  TEST_CASE("a vertex moved to x = 0 (a long thin spike) finishes instead of hanging") {
    const fs::path d = scratch("coast_x0");
    // Bali, vertex 43 moved 81 km west: was no answer after 60 s (repair rounds
    // multiplied the cells while the inverted region grew). Now the repair
    // stops after a round or two and the map is certified on a T-mesh of a few
    // hundred cells (676 when this was written).
    const auto r = param(move_vertex(coastline("bali.txt"), 43, 0, "0", d / "bali_x0.txt"), d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json rep = nlohmann::json::parse(test_support::slurp(d / "out" / "report.json"));
    CHECK(rep["certified_valid"] == true);
    CHECK(rep["optimization"]["repair_rounds"].get<int>() <= 2);
    CHECK(rep["optimization"]["tangled_nodes_after"] == 0);
    CHECK(rep["counts"]["cells"].get<int>() <= 2000);
  }

  TEST_CASE("the front half stops with a message when the polygon needs more than max_cells") {
    // The disk's boundary needs a few hundred cells at the default tolerance.
    const tspline::Polygon p = tspline::io::read_polygon(test_support::polygon_file("disk.txt"));
    tspline::ParameterizationOptions opt;
    opt.max_cells = 100;
    for (int trials : {1, 4}) {  // with automatic corner trials too
      opt.corner_trials = trials;
      const std::string msg = test_support::message_of<tspline::InputError>([&] { tspline::run_front(p, opt); });
      CHECK(contains(msg, "needs more than 100 cells (`max_cells`)"));
    }
    // With room, the same polygon is meshed within the budget.
    opt.max_cells = 1000;
    const tspline::FrontResult r = tspline::run_front(p, opt);
    CHECK(r.mesh.num_cells() <= opt.max_cells);
    CHECK(r.quality_optimized.inverted_cells == 0);
  }

  TEST_CASE("automatic corners of a polygon whose perimeter is nearly all one spike: four convex vertices") {
    // Most snapped candidate positions fall on the spike's two long edges and
    // coincide (this returned no candidate at all, and run_front indexed it).
    std::vector<Eigen::Vector2d> v;
    for (int k = 0; k < 12; ++k) v.emplace_back(k / 11.0, 0.0);
    v.emplace_back(1, 1), v.emplace_back(0.51, 1), v.emplace_back(0.5, 1e7), v.emplace_back(0.49, 1);
    v.emplace_back(0, 1);
    const tspline::Polygon p = tspline::validate_polygon(test_support::make_polygon(v));
    const std::vector<tspline::Corners> c = tspline::corner_candidates(p, 4);
    REQUIRE(!c.empty());
    for (const tspline::Corners& ch : c)
      for (int k = 0; k < 4; ++k) {
        CAPTURE(ch.index[k]);
        CHECK(ch.inner_angle_deg[k] < 180.0);
      }
  }

  TEST_CASE("GeoJSON with a number beyond the range of doubles: an InputError, not an internal error") {
    // Found by fuzz_geojson (in the reader of that time): 51e308 overflows a double.
    const std::string doc = R"({"type":"Polygon","coordinates":[[[0,0],[51e308,0],[1,1],[0,1]]]})";
    const std::string msg = test_support::message_of<tspline::InputError>(
        [&] { tspline::io::read_geojson_domain(doc, {}, "big.geojson"); });
    CHECK(contains(msg, "big.geojson"));
  }

  TEST_CASE("--omega 2.5, --max-sweeps -1, --sweep-tol -1: input errors naming the option, not internal errors") {
    const fs::path d = scratch("options");
    const std::string square = test_support::polygon_file("square.txt");
    const struct {
      std::string args, names;
    } cases[] = {{"--omega 2.5", "--omega must be in [1, 2)"},
                 {"--omega nan", "--omega"},
                 {"--max-sweeps -1", "--max-sweeps must be >= 1"},
                 {"--sweep-tol -1", "--sweep-tol must be a positive finite number"},
                 {"--max-cells 0", "--max-cells must be >= 1"}};
    for (const auto& c : cases) {
      const auto r = param(square, d, c.args);
      CHECK(r.exit_code == 1);
      CHECK(contains(r.err, c.names));
      CHECK(!fs::exists(d / "out" / "tspline.json"));
    }
  }

  TEST_CASE("Ctrl-C (SIGINT) during a long run: exit 130, one line, no half-written or partial outputs") {
    const fs::path d = scratch("sigint");
    const fs::path out = d / "out", so = d / "stdout.txt", se = d / "stderr.txt";
    // The child writes its progress to files; started with posix_spawn so that
    // the test knows its pid.
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, so.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, se.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const std::string exe = TSPLINE_APP_PATH, input = coastline("corsica.txt"), out_s = out.string();
    std::vector<char*> argv = {const_cast<char*>(exe.c_str()), const_cast<char*>("param"),
                               const_cast<char*>(input.c_str()), const_cast<char*>("--out"),
                               const_cast<char*>(out_s.c_str()), nullptr};
    pid_t pid = 0;
    REQUIRE(posix_spawn(&pid, exe.c_str(), &fa, nullptr, argv.data(), environ) == 0);
    posix_spawn_file_actions_destroy(&fa);
    // Wait until the run is under way (its first optimization line), then interrupt.
    const auto start = std::chrono::steady_clock::now();
    while (!contains(test_support::slurp(so), "optimization") &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(120))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    REQUIRE(contains(test_support::slurp(so), "optimization"));
    const auto sent = std::chrono::steady_clock::now();
    REQUIRE(::kill(pid, SIGINT) == 0);
    int status = 0;
    REQUIRE(::waitpid(pid, &status, 0) == pid);
    const double latency = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
    MESSAGE("stopped " << latency << " s after SIGINT");
    REQUIRE(WIFEXITED(status));  // not killed by the signal: it stopped itself
    CHECK(WEXITSTATUS(status) == 130);
    const std::string err = test_support::slurp(se);
    CHECK(count_lines(err) == 1);
    CHECK(err.rfind("tspline: interrupted: stopped by SIGINT", 0) == 0);
    // The run stopped before the outputs: none of them, and no temporary file.
    for (const char* f : {"tspline.json", "surface.vtu", "report.json", "adapt.pvd"})
      CHECK(!fs::exists(out / f));
    if (fs::exists(out))
      for (const auto& e : fs::recursive_directory_iterator(out)) {
        CAPTURE(e.path());
        CHECK(!contains(e.path().filename().string(), ".tmp."));
      }
  }
}
