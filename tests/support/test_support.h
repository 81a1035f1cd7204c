#pragma once
// Helpers shared by the test suites.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"
#include "tspline/tmesh/tmesh.h"

namespace test_support {

/// Path of a bundled test polygon, e.g. polygon_file("disk.txt").
inline std::string polygon_file(const std::string& file_name) {
  // (Appended, not a chain of +: GCC 12 warns falsely of -Warray-bounds on that.)
  std::string path = TSPLINE_TEST_DATA_DIR;
  return path.append("/polygons/").append(file_name);
}

/// A polygon with the identity file numbering.
inline tspline::Polygon make_polygon(const std::vector<Eigen::Vector2d>& v) {
  tspline::Polygon p;
  p.vertices = v;
  for (std::size_t i = 0; i < v.size(); ++i) p.file_index.push_back(i);
  return p;
}

/// The message of the exception of type E thrown by f (fails the test if none).
template <class E, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  FAIL("no exception of the expected type");
  return {};
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// Whole content of a file ("" if unreadable).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// A fresh, empty scratch directory for one test (under the system temp dir,
/// per process, so concurrent runs do not collide).
inline std::filesystem::path scratch_dir(const std::string& suite, const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  ("tspline_" + suite + "_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline std::size_t count_lines(const std::string& s) {
  return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

/// The path in single quotes for the shell (built piecewise: GCC 12 warns,
/// falsely, -Wrestrict on "'" + s + "'").
inline std::string quoted(const std::filesystem::path& p) {
  std::string s = "'";
  s += p.string();
  s += '\'';
  return s;
}

/// One run of the built `tspline` command.
struct AppRun {
  int exit_code = -1;
  std::string out, err;
};

/// Runs the program `exe` with ARGS (shell syntax), stdout and stderr captured
/// in files of `dir`.
inline AppRun run_program(const std::string& exe, const std::string& args, const std::filesystem::path& dir) {
  const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = "'" + exe + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  AppRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// `r` after requiring that it exited with 0 (its stdout and stderr shown if not).
inline AppRun require_success(AppRun r) {
  CAPTURE(r.out);
  CAPTURE(r.err);
  REQUIRE(r.exit_code == 0);
  return r;
}

/// Runs `tspline ARGS` (or another built program) with stdout and stderr captured in files of `dir`.
inline AppRun run_app(const std::string& args, const std::filesystem::path& dir,
                      const std::string& program = TSPLINE_APP_PATH) {
  return run_program(program, args, dir);
}

/// A bad invocation of `tspline`: its arguments, a part of the one error line
/// it must print, and its exit code.
struct BadInvocation {
  std::string args, needle;
  int code;
};

/// Runs `c` (run_app in `dir`) and checks its exit code and its one error line;
/// returns the run for further checks.
inline AppRun check_bad_invocation(const BadInvocation& c, const std::filesystem::path& dir) {
  const AppRun r = run_app(c.args, dir);
  CAPTURE(c.args);
  CAPTURE(r.err);
  CHECK(r.exit_code == c.code);
  CHECK(count_lines(r.err) == 1);
  CHECK(contains(r.err, c.needle));
  return r;
}

/// `tspline param POLYGON -q --out OUT [OPTIONS]` on a bundled polygon
/// (polygon_file), required to succeed; returns the map's file OUT/tspline.json.
inline std::filesystem::path param_polygon(const std::string& polygon, const std::filesystem::path& out,
                                           const std::string& options = "") {
  const AppRun r = run_app("param " + quoted(std::filesystem::path(polygon_file(polygon))) + " -q --out " +
                               quoted(out) + (options.empty() ? "" : " " + options),
                           out.parent_path());
  CAPTURE(r.err);
  REQUIRE(r.exit_code == 0);
  return out / "tspline.json";
}

/// A balanced T-mesh from the uniform 4x4 mesh by `rounds` splits of the leaves
/// containing random points (leaves of level max_level are not split).
inline tspline::TMesh random_tmesh(unsigned seed, int rounds, int max_level) {
  std::mt19937 rng(seed);
  tspline::TMesh m(2);
  std::uniform_int_distribution<std::int64_t> pick(0, tspline::TMesh::kRoot - 1);
  for (int r = 0; r < rounds; ++r) {
    const int n = m.leaf_at_doubled(2 * pick(rng) + 1, 2 * pick(rng) + 1);
    if (m.node(n).level < max_level) m.refine(n);
  }
  m.balance();
  m.build_topology();
  return m;
}

/// Uniform level-`level` mesh, then `splits` splits of random leaves of level
/// below `max_level`, then a balance.
inline tspline::TMesh random_leaf_splits(int level, int splits, unsigned seed, int max_level = 6) {
  tspline::TMesh m(level);
  std::mt19937 rng(seed);
  for (int s = 0; s < splits; ++s) {
    std::vector<int> leaves;
    for (std::size_t n = 0; n < m.nodes().size(); ++n)
      if (m.node(static_cast<int>(n)).is_leaf() && m.node(static_cast<int>(n)).level < max_level)
        leaves.push_back(static_cast<int>(n));
    m.refine(leaves[std::uniform_int_distribution<std::size_t>(0, leaves.size() - 1)(rng)]);
  }
  m.balance();
  m.build_topology();
  return m;
}

}  // namespace test_support
