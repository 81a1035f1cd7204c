#include "param_multipatch.h"

#include <chrono>
#include <iostream>
#include <sstream>

#include "tspline/errors.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/param_output.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/multipatch/multipatch_parameterization.h"

namespace tspline_app {

int run_multipatch_param(const tspline::io::DomainInput& input_domain, const std::string& input,
                         const std::string& out_dir, const std::string& cuts_file,
                         const tspline::ParameterizationOptions& options, const tspline::AdaptiveOptions& adaptive,
                         int samples, Progress& progress) {
  if (options.corners) throw tspline::InputError("--corners applies to a single patch; a domain with holes is cut "
                                                 "into patches whose corners are the ends of the cuts");
  const auto t0 = std::chrono::steady_clock::now();
  tspline::Domain domain{input_domain.outer, input_domain.holes};
  std::optional<std::vector<tspline::Cut>> cuts;
  if (!cuts_file.empty()) {
    cuts.emplace();
    for (const tspline::Polygon& p : tspline::io::read_text_rings(cuts_file)) cuts->push_back(p.vertices);
  }
  const tspline::MultiPatchResult R = tspline::run_multipatch_parameterization(
      domain, cuts, options, adaptive, {}, [&](std::size_t p, int round) {
        progress.event({{"event", "patch"}, {"patch", p}, {"round", round}});
      });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::json report = tspline::io::multipatch_report(R, input, seconds);
  report["input_geometry"] = input_domain.description;
  tspline::io::write_multipatch_outputs(R, out_dir, report, samples);
  progress.settle();
  const auto& totals = report["totals"];
  progress.event({{"event", "result"},
                  {"valid", R.valid()},
                  {"certified_valid", R.certified_valid()},
                  {"patches", R.patches.size()},
                  {"cells", totals["cells"]},
                  {"min_mean_ratio_jacobian", R.min_mean_ratio_gauss()},
                  {"whole_map", totals["whole_map"]},
                  {"max_interface_gap", R.max_gap()},
                  {"out", out_dir}});
  if (progress.human()) {
    std::ostringstream s;
    s << R.patches.size() << " patches, " << R.layout.cuts.size() << " cuts, " << totals["cells"] << " cells, "
      << totals["bezier_elements"] << " elements; certified " << (R.certified_valid() ? "valid" : "NOT valid")
      << " (det J >= " << R.min_relative_det_bound() << " x element mean); "
      << tspline::io::whole_map_quality_summary(totals["whole_map"]) << "; area " << R.map_area << " vs "
      << R.domain_area << "; largest interface gap " << R.max_gap()
      << " (" << R.max_gap() / R.diameter << " x diameter); " << seconds << " s";
    std::cout << s.str() << "\nwrote tspline.json (format version 2), surface.vtu, control_net.vtu, "
                            "parametric_tmesh.vtu, physical_tmesh.vtu, boundary.vtu, report.json to "
              << out_dir << std::endl;
  }
  if (!R.conforming(tspline::MultiPatchOptions{}.gap_tolerance)) {
    std::cerr << "tspline: error: the map is not watertight: the two images of a cut differ by up to " << R.max_gap()
              << " (" << R.max_gap() / R.diameter << " x diameter) after " << R.sync_rounds
              << " rounds of re-running patches with shared knots (files written; see report.json, interfaces)"
              << std::endl;
    return 3;
  }
  if (!R.certified_valid() && adaptive.certify) {
    for (std::size_t p = 0; p < R.patches.size(); ++p)
      if (!R.patches[p].certified_valid())
        std::cerr << "tspline: error: patch " << p << " is not certified valid: " << R.patches[p].stop_reason
                  << std::endl;
    return 3;
  }
  return 0;
}

}  // namespace tspline_app
