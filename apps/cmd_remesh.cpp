// meshopt remesh: the run (meshopt_remesh.cpp) and its summary, from its report.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "meshopt_runs.h"
#include "progress.h"

namespace meshopt_app {

int run_remesh(const RemeshArgs& a) {
  tspline_app::Progress out(tspline_app::output_mode(a.quiet, a.json));
  const nlohmann::json j = remesh_model(a, out);
  const nlohmann::json &before = j["before"], &after = j["after"], &dev = j["chordal_deviation"],
                       &ops = j["operations"], &seconds = j["seconds"];
  auto num = [](const nlohmann::json& v) { return v.get<double>(); };
  auto count = [](const nlohmann::json& v) { return v.get<std::size_t>(); };
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "meshopt remesh: %zu patches, %zu feature curves, L %g, s %g, D %g\n"
      "before  %7zu vertices %8zu triangles\n"
      "after   %7zu vertices %8zu triangles   6D length/L mean %.3f [%.3f, %.3f]   min 6D angle "
      "mean %.1f min %.1f deg\n"
      "3D aspect ratio min %.4f mean %.3f   chordal deviation max %.3g mean %.3g (%.2e / %.2e of the "
      "diagonal)\n"
      "%zu splits, %zu collapses, %zu flips, %zu smoothing moves; %.2f s sampling, %.2f s optimizing",
      count(j["patches"]), count(j["feature_curves"]), num(j["length"]), num(j["anisotropy"]),
      num(j["max_deviation"]), count(before["vertices"]), count(before["triangles"]),
      count(after["vertices"]), count(after["triangles"]), num(after["length6d_over_L"]["mean"]),
      num(after["length6d_over_L"]["min"]), num(after["length6d_over_L"]["max"]),
      num(after["min_angle6d_degrees"]["mean"]), num(after["min_angle6d_degrees"]["min"]),
      num(after["aspect_ratio3d"]["min"]), num(after["aspect_ratio3d"]["mean"]), num(dev["max"]),
      num(dev["mean"]), num(dev["max_relative"]), num(dev["mean_relative"]), count(ops["splits"]),
      count(ops["collapses"]), count(ops["flips"]), count(ops["smoothing_moves"]), num(seconds["sampling"]),
      num(seconds["optimizing"]));
  out.log(buf);
  const std::string vtu = j["outputs"]["vtu"];
  out.log("wrote " + a.out + (vtu.empty() ? "" : ", " + vtu) + ", " +
          j["outputs"]["report"].get<std::string>());
  out.event({{"event", "result"}, {"report", j}});
  return 0;
}

}  // namespace meshopt_app
