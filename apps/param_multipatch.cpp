#include "param_multipatch.h"

#include <iostream>
#include <sstream>

#include "tspline/errors.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/param_output.h"

namespace tspline_app {

int write_multipatch_param(const tspline::DomainParameterization& P, const tspline::io::DomainInput& input_domain,
                           const std::string& input, const std::string& out_dir,
                           const tspline::AdaptiveOptions& adaptive, int samples, double seconds, Progress& progress,
                           const std::vector<std::string>& cleaning_notes) {
  const tspline::MultiPatchResult& R = *P.patches;
  nlohmann::json report = tspline::io::multipatch_report(R, input, seconds);
  report["input_geometry"] = input_domain.description;
  report["input_cleaning"] = {{"notes", cleaning_notes}};
  report["layout"] = {{"chosen", P.layout}, {"reason", P.reason}, {"explanation", R.cuts_explanation}};
  if (P.quad_stats) {
    const tspline::QuadLayoutStats& s = *P.quad_stats;
    report["layout"]["quad"] = {{"patches", s.patches},
                                {"ring_nodes", s.ring_nodes},
                                {"inner_nodes", s.inner_nodes},
                                {"inner_valence", s.valence},
                                {"straight_min_scaled_jacobian", s.min_corner_scaled_jacobian},
                                {"straight_mean_scaled_jacobian", s.mean_corner_scaled_jacobian},
                                {"repair_rounds", s.repair_rounds},
                                {"pillowed_rings", s.pillowed_rings},
                                {"optimization_level", s.optimization_level},
                                {"rotations", s.rotations},
                                {"optimization_sweeps", s.optimization_sweeps},
                                {"corner_mean_ratio", s.corner_mean_ratio},
                                {"corner_scaled_jacobian", s.corner_scaled_jacobian},
                                {"min_size", s.min_size},
                                {"max_size", s.max_size},
                                {"seconds", s.seconds}};
  }
  if (P.rejected_single)
    report["layout"]["single_patch_first_try"] = {{"min_scaled_jacobian_dense", P.rejected_single->min_scaled},
                                                  {"min_mean_ratio_dense", P.rejected_single->min_mean_ratio}};
  tspline::io::write_multipatch_outputs(R, out_dir, report, samples);
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
