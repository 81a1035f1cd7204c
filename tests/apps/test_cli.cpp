// The command line as a user meets it: --version, --help for every command
// with the defaults shown, machine-readable --json progress, --quiet.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "test_support.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/pipeline/parameterization.h"

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::contains;
using test_support::run_app;

namespace {

fs::path scratch(const std::string& name) { return test_support::scratch_dir("cli", name); }
std::string q(const fs::path& p) { return test_support::quoted(p); }

/// Every stdout line parsed as JSON (fails the test on a line that is not).
std::vector<json> json_lines(const std::string& out) {
  std::vector<json> v;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    CAPTURE(line);
    REQUIRE_NOTHROW(v.push_back(json::parse(line)));
    REQUIRE(v.back().contains("event"));
  }
  return v;
}

/// The help line that documents `option` (it starts with the option's name).
std::string option_line(const std::string& help, const std::string& option) {
  std::istringstream in(help);
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(' ');
    if (first != std::string::npos && line.compare(first, option.size() + 1, option + " ") == 0) return line;
  }
  FAIL("no help line for " << option << " in:\n" << help);
  return {};
}

/// A default value as CLI11 prints it (operator<<).
template <class T>
std::string str(const T& v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("--version and --help for every command, defaults shown") {
    const fs::path d = scratch("help");
    const auto v = run_app("--version", d);
    CHECK(v.exit_code == 0);
    CHECK(contains(v.out, "tspline 0.1.0"));
    const auto top = run_app("--help", d);
    CHECK(top.exit_code == 0);
    for (const char* cmd : {"param", "poisson", "render", "eval", "info"}) CHECK(contains(top.out, cmd));
    struct Expect {
      std::string command;
      std::vector<std::string> options;  ///< each must appear, with its default where it has one
    };
    const std::vector<Expect> expect = {
        {"param", {"--out", "--corners", "--tol-rel", "--init-level", "--min-jacobian", "--json", "--quiet"}},
        {"poisson", {"--problem", "--refine", "--steps", "--gamma", "--max-dofs", "--json", "--quiet"}},
        {"render", {"--png", "--view", "--size", "--step"}},
    };
    for (const Expect& e : expect) {
      CAPTURE(e.command);
      const auto h = run_app(e.command + " --help", d);
      CHECK(h.exit_code == 0);
      for (const auto& o : e.options) {
        CAPTURE(o);
        CHECK(contains(h.out, o));
      }
    }
    // Defaults are printed on the option's own line, and they are the
    // library's defaults (param) or the documented ones (poisson, render).
    const std::string param_help = run_app("param --help", d).out;
    const tspline::AdaptiveOptions adaptive;
    const tspline::ParameterizationOptions front;
    // "=" + value (appended: GCC 12's -Wrestrict misfires on operator+(const char*, string&&)).
    auto eq = [](const std::string& value) {
      std::string s = "=";
      s += value;
      return s;
    };
    CHECK(contains(option_line(param_help, "--min-jacobian"), eq(str(adaptive.min_jacobian))));
    CHECK(contains(option_line(param_help, "--max-adapt"), eq(str(adaptive.max_adapt))));
    CHECK(contains(option_line(param_help, "--max-cells"), eq(str(front.max_cells))));
    CHECK(contains(option_line(param_help, "--init-level"), eq(str(front.initial_level))));
    CHECK(contains(option_line(param_help, "--tol-rel"), eq(str(front.tolerance_relative))));
    CHECK(contains(option_line(param_help, "--omega"), eq(str(front.smoothing.over_relaxation))));
    CHECK(contains(option_line(run_app("poisson --help", d).out, "--gamma"), "=0.5"));
    CHECK(contains(option_line(run_app("render --help", d).out, "--size"), "=1200x900"));
    // A wrong option says where to look.
    const auto bad = run_app("param --bogus", d);
    CHECK(bad.exit_code == 1);
    CHECK(contains(bad.err, "--help"));
  }

  TEST_CASE("--json: one JSON object per line, ending with the result; --quiet prints nothing") {
    const fs::path d = scratch("json");
    const auto p = run_app("param --layout single " + q(test_support::polygon_file("square.txt")) + " --json --out " + q(d / "sq"), d);
    CAPTURE(p.err);
    REQUIRE(p.exit_code == 0);
    const auto events = json_lines(p.out);
    REQUIRE(events.size() >= 3);
    int iterations = 0;
    for (const json& e : events) iterations += e["event"] == "iteration";
    CHECK(iterations >= 1);
    const json& result = events.back();
    CHECK(result["event"] == "result");
    CHECK(result["valid"] == true);
    CHECK(result["min_mean_ratio_jacobian"].get<double>() > 0.99);  // the square maps onto itself

    const auto s = run_app("poisson " + q(d / "sq" / "tspline.json") +
                               " --problem sinsin --refine uniform --steps 3 --json --out " + q(d / "poisson"),
                           d);
    CAPTURE(s.err);
    REQUIRE(s.exit_code == 0);
    const auto pe = json_lines(s.out);
    std::vector<json> steps;
    for (const json& e : pe)
      if (e["event"] == "step") steps.push_back(e);
    REQUIRE(steps.size() == 3);
    CHECK(steps[2]["dofs"].get<int>() > steps[0]["dofs"].get<int>());
    CHECK(steps[2]["h1"].get<double>() < steps[0]["h1"].get<double>());
    CHECK(pe.back()["event"] == "result");
    CHECK(pe.back()["steps"] == 3);

    const auto quiet = run_app("param --layout single " + q(test_support::polygon_file("square.txt")) + " -q --out " + q(d / "q"), d);
    CHECK(quiet.exit_code == 0);
    CHECK(quiet.out.empty());
    CHECK(quiet.err.empty());
  }
}
