// `tspline param MOVED --from OLD/tspline.json`: the warm start from the command
// line. No motion writes the same control points; a rigid motion the moved
// ones; a boundary that does not match, or a multi-patch file, is an input
// error (exit 1) that names the problem and writes nothing.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"

namespace fs = std::filesystem;
using test_support::contains;
using test_support::run_program;

namespace {

std::string q(const fs::path& p) { return test_support::quoted(p); }

std::vector<Eigen::Vector2d> control_points(const fs::path& tspline_json) {
  std::ifstream in(tspline_json);
  const nlohmann::json doc = nlohmann::json::parse(in);
  std::vector<Eigen::Vector2d> out;
  for (const auto& f : doc.at("functions"))
    out.emplace_back(f.at("control_point")[0].get<double>(), f.at("control_point")[1].get<double>());
  return out;
}

void write_ring(const fs::path& path, const std::vector<Eigen::Vector2d>& v) {
  std::ofstream out(path);
  out.precision(17);
  for (const auto& p : v) out << p.x() << ' ' << p.y() << '\n';
}

// `tspline param DOMAIN --quiet --from DIR/first/tspline.json --out DIR/OUT`:
// a warm start from the test's first run in DIR, required to succeed.
void warm_start(const fs::path& dir, const fs::path& domain, const std::string& out) {
  const auto r = run_program(TSPLINE_APP_PATH,
                             "param " + q(domain) + " --quiet --from " + q(dir / "first" / "tspline.json") +
                                 " --out " + q(dir / out),
                             dir);
  CAPTURE(r.err);
  REQUIRE(r.exit_code == 0);
}

}  // namespace

TEST_SUITE("param_from_app") {
  TEST_CASE("tspline param --from: no motion, a rigid motion, and mismatched inputs") {
    const fs::path d = test_support::scratch_dir("param_from", "isle_of_man");
    const std::string coast = std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/isle_of_man.txt";
    const auto first = run_program(TSPLINE_APP_PATH, "param " + q(coast) + " --quiet --out " + q(d / "first"), d);
    REQUIRE(first.exit_code == 0);
    const std::vector<Eigen::Vector2d> P = control_points(d / "first" / "tspline.json");

    const auto same = run_program(TSPLINE_APP_PATH,
                                  "param " + q(coast) + " --from " + q(d / "first" / "tspline.json") + " --out " +
                                      q(d / "same"),
                                  d);
    CAPTURE(same.err);
    REQUIRE(same.exit_code == 0);
    CHECK(contains(same.out, "warm start"));
    const std::vector<Eigen::Vector2d> S = control_points(d / "same" / "tspline.json");
    REQUIRE(S.size() == P.size());
    double err = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i) err = std::max(err, (S[i] - P[i]).norm());
    CHECK(err < 1e-11);  // km coordinates of an island 50 km across

    // The file's vertices rotated by 30 degrees about the origin and shifted.
    std::vector<Eigen::Vector2d> ring;
    {
      std::ifstream in(coast);
      std::string line;
      while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream s(line);
        double x = 0, y = 0;
        s >> x >> y;
        ring.emplace_back(x, y);
      }
    }
    const double th = M_PI / 6;
    Eigen::Matrix2d R;
    R << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
    const Eigen::Vector2d t(-20.0, 7.5);
    std::vector<Eigen::Vector2d> rotated;
    for (const auto& p : ring) rotated.push_back(R * p + t);
    write_ring(d / "rotated.txt", rotated);
    warm_start(d, d / "rotated.txt", "rigid");
    const std::vector<Eigen::Vector2d> M = control_points(d / "rigid" / "tspline.json");
    REQUIRE(M.size() == P.size());
    err = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i) err = std::max(err, (M[i] - (R * P[i] + t)).norm());
    CHECK(err < 1e-11);

    // A moved ring `name`.txt that is no move of the first one: an input error
    // saying why, and no output folder.
    auto rejected_move = [&](const std::string& name, const std::vector<Eigen::Vector2d>& moved,
                             const std::string& message) {
      CAPTURE(name);
      write_ring(d / (name + ".txt"), moved);
      const auto r = run_program(TSPLINE_APP_PATH,
                                 "param " + q(d / (name + ".txt")) + " --from " + q(d / "first" / "tspline.json") +
                                     " --out " + q(d / name),
                                 d);
      CHECK(r.exit_code == 1);
      CHECK(contains(r.err, message));
      CHECK(!fs::exists(d / name / "tspline.json"));
    };
    // One vertex fewer: the message names the counts.
    rejected_move("short", std::vector<Eigen::Vector2d>(ring.begin(), ring.end() - 1),
                  "the outer ring of the moved boundary has 71 vertices");
    // Two vertices swapped: the ring crosses itself (edges named by file index).
    std::vector<Eigen::Vector2d> crossing = ring;
    std::swap(crossing[5], crossing[40]);
    rejected_move("crossing", crossing, "not simple");
    // A layout option with --from: the layout is the previous map's.
    const auto layout = run_program(TSPLINE_APP_PATH,
                                    "param " + q(coast) + " --layout quad --from " +
                                        q(d / "first" / "tspline.json") + " --out " + q(d / "layout"),
                                    d);
    CHECK(layout.exit_code == 1);
    CHECK(contains(layout.err, "the layout is the previous map's"));
    // Not a T-spline file.
    const auto bad = run_program(TSPLINE_APP_PATH,
                                 "param " + q(coast) + " --from " + q(coast) + " --out " + q(d / "bad"), d);
    CHECK(bad.exit_code == 1);
    CHECK(!fs::exists(d / "bad" / "tspline.json"));
  }

  TEST_CASE("tspline param --from on a multi-patch map: a rigid motion moves every patch; old files are refused") {
    const fs::path d = test_support::scratch_dir("param_from", "plate");
    const std::string plate = std::string(TSPLINE_TEST_DATA_DIR) + "/holes/plate_with_hole.txt";
    const auto first = run_program(TSPLINE_APP_PATH, "param " + q(plate) + " --quiet --out " + q(d / "first"), d);
    REQUIRE(first.exit_code == 0);
    // The rings of the file moved by a rotation and a translation, blank lines between rings kept.
    const double th = 0.3;
    std::ifstream in(plate);
    std::ofstream out(d / "moved.txt");
    out.precision(17);
    std::string line;
    while (std::getline(in, line)) {
      double x = 0, y = 0;
      std::istringstream s(line);
      if (line.empty() || line[0] == '#' || !(s >> x >> y)) {
        out << line << '\n';
        continue;
      }
      out << std::cos(th) * x - std::sin(th) * y + 5.0 << ' ' << std::sin(th) * x + std::cos(th) * y - 2.0 << '\n';
    }
    out.close();
    warm_start(d, d / "moved.txt", "moved");
    std::ifstream a(d / "first" / "tspline.json"), b(d / "moved" / "tspline.json");
    const nlohmann::json A = nlohmann::json::parse(a), B = nlohmann::json::parse(b);
    REQUIRE(A.at("patches").size() == B.at("patches").size());
    CHECK(B.contains("domain"));
    double err = 0.0;
    for (std::size_t p = 0; p < A["patches"].size(); ++p) {
      const auto& fa = A["patches"][p]["functions"];
      const auto& fb = B["patches"][p]["functions"];
      REQUIRE(fa.size() == fb.size());
      for (std::size_t i = 0; i < fa.size(); ++i) {
        const double x = fa[i]["control_point"][0], y = fa[i]["control_point"][1];
        const Eigen::Vector2d want(std::cos(th) * x - std::sin(th) * y + 5.0, std::sin(th) * x + std::cos(th) * y - 2.0);
        err = std::max(err, (Eigen::Vector2d(fb[i]["control_point"][0], fb[i]["control_point"][1]) - want).norm());
      }
    }
    CHECK(err < 1e-12);
    // A version-2 file without the domain's rings (written before they were recorded).
    nlohmann::json old = A;
    old.erase("domain");
    std::ofstream(d / "old.json") << old.dump();
    const auto refused = run_program(TSPLINE_APP_PATH,
                                     "param " + q(d / "moved.txt") + " --from " + q(d / "old.json") + " --out " +
                                         q(d / "refused"),
                                     d);
    CHECK(refused.exit_code == 1);
    CHECK(contains(refused.err, "does not record the rings"));
    CHECK(!fs::exists(d / "refused" / "tspline.json"));
  }
}
