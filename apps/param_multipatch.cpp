#include "param_multipatch.h"

#include <iostream>
#include <sstream>

#include "param_options.h"
#include "tspline/errors.h"
#include "tspline/io/param_output.h"

namespace tspline_app {

int write_multipatch_param(const ParamRun& run, const std::string& out_dir, Progress& progress) {
  const tspline::DomainParameterization& P = run.result;
  const tspline::MultiPatchResult& R = *P.patches;
  const tspline::AdaptiveOptions& adaptive = run.settings.adaptive;
  const nlohmann::json& report = run.report;
  const double seconds = run.seconds;
  progress.log("writing the output files to " + out_dir);
  write_param_run(run, out_dir);
  progress.settle();
  const auto& totals = report["totals"];
  progress.event({{"event", "result"},
                  {"valid", R.valid()},
                  {"certified_valid", R.certified_valid()},
                  {"layout", P.layout},
                  {"patches", R.patches.size()},
                  {"cells", totals["cells"]},
                  {"min_mean_ratio_jacobian", R.min_mean_ratio_gauss()},
                  {"whole_map", totals["whole_map"]},
                  {"max_interface_gap", R.max_gap()},
                  {"out", out_dir}});
  if (progress.human()) {
    std::ostringstream s;
    s << "layout " << P.layout << " (" << P.reason << "): " << R.patches.size() << " patches, "
      << R.layout.cuts.size() << " cuts, " << totals["cells"] << " cells, " << totals["bezier_elements"]
      << " elements; certified " << (R.certified_valid() ? "valid" : "NOT valid") << " (det J >= "
      << R.min_relative_det_bound() << " x element mean); "
      << tspline::io::whole_map_quality_summary(totals["whole_map"]) << "; area " << R.map_area << " vs "
      << R.domain_area << "; largest interface gap " << R.max_gap() << " (" << R.max_gap() / R.diameter
      << " x diameter); " << seconds << " s";
    std::string files;
    for (const std::string& f : param_run_files(run))
      files += (files.empty() ? "" : ", ") + f + (f == "tspline.json" ? " (format version 2)" : "");
    std::cout << s.str() << "\nwrote " << files << " to " << out_dir << std::endl;
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
        std::cerr << "tspline: error: patch " << p << " is not certified valid: " << with_option_names(R.patches[p].stop_reason, Spelling::Cli)
                  << std::endl;
    return 3;
  }
  return 0;
}

}  // namespace tspline_app
