#pragma once
// Shared helpers of the `tspline poisson` end-to-end suites: their geometry
// maps, the convergence table, the comparison of two runs' errors, and runs
// under mpirun.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "test_support.h"

namespace test_support {

/// tspline.json of a bundled polygon as one patch (`tspline param --layout
/// single`), made once per process and suite, in the suite's scratch folder.
inline std::filesystem::path single_patch_map(const std::string& suite, const std::string& polygon) {
  static std::map<std::pair<std::string, std::string>, std::filesystem::path> made;
  const auto key = std::make_pair(suite, polygon);
  if (const auto it = made.find(key); it != made.end()) return it->second;
  const std::filesystem::path file =
      param_polygon(polygon, scratch_dir(suite, "geometry_" + polygon) / "out", "--layout single");
  return made[key] = file;
}

/// convergence.csv as one map column -> text per row.
inline std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) out.push_back(item);
    if (!s.empty() && s.back() == ',') out.emplace_back();
    return out;
  };
  if (!std::getline(f, line)) return rows;
  header = split(line);
  while (std::getline(f, line)) {
    const auto cols = split(line);
    REQUIRE(cols.size() == header.size());
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < cols.size(); ++i) row[header[i]] = cols[i];
    rows.push_back(row);
  }
  return rows;
}

/// A number of a convergence.csv row (present and not empty).
inline double csv_number(const std::map<std::string, std::string>& row, const std::string& col) {
  REQUIRE(row.count(col) == 1);
  REQUIRE(!row.at(col).empty());
  return std::stod(row.at(col));
}

/// report.json of a poisson run.
inline nlohmann::json poisson_report(const std::filesystem::path& out) {
  return nlohmann::json::parse(slurp(out / "report.json"));
}

/// `tspline poisson MAP ARGS --out DIR/OUT`, which must succeed; its report.json.
inline nlohmann::json run_poisson(const std::filesystem::path& map, const std::string& args,
                                  const std::filesystem::path& dir, const std::string& out = "out") {
  const AppRun r = run_app("poisson " + quoted(map) + " " + args + " --out " + quoted(dir / out), dir);
  CAPTURE(r.err);
  REQUIRE(r.exit_code == 0);
  return poisson_report(dir / out);
}

/// Every step of b has the DOFs of a and L2 and H1 errors equal to 1e-6 relative.
inline void check_same_errors(const nlohmann::json& a, const nlohmann::json& b) {
  REQUIRE(a["steps"].size() == b["steps"].size());
  for (std::size_t k = 0; k < a["steps"].size(); ++k) {
    const nlohmann::json &sa = a["steps"][k], &sb = b["steps"][k];
    CAPTURE(k);
    REQUIRE(sa["dofs"] == sb["dofs"]);
    for (const char* e : {"l2", "h1"}) {
      CAPTURE(e);
      const double ea = sa[e].get<double>(), eb = sb[e].get<double>();
      CHECK(ea > 0);
      CHECK(std::abs(ea - eb) <= 1e-6 * ea);
    }
  }
}

/// `mpirun -n P tspline ARGS` (as root too; oversubscribed if there are fewer cores).
inline AppRun run_mpi(int processes, const std::string& args, const std::filesystem::path& dir) {
  return run_program("/usr/bin/env",
                     "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n " +
                         std::to_string(processes) + " --oversubscribe " + quoted(TSPLINE_APP_PATH) + " " + args,
                     dir);
}

}  // namespace test_support
