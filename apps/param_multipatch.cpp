#include "param_multipatch.h"

#include <chrono>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/errors.h"
#include "tspline/io/multipatch_output.h"
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
  // Every ring is cleaned here with the run's boundary tolerance (needles
  // narrower than epsilon / diagonal go, one note per cleaned ring); the
  // pipeline's own validate_domain then finds nothing more to remove.
  std::vector<std::string> cleaning_notes;
  tspline::Domain domain;
  {
    tspline::DomainCleaningOptions how;
    how.needle_width =
        tspline::needle_width_for_ring(input_domain.outer, options.tolerance_absolute, options.tolerance_relative);
    how.notes = &cleaning_notes;
    auto report_notes = [&] {
      for (const std::string& note : cleaning_notes)
        tspline::report_step(options.progress, "cleaning", "note: " + note, -1, tspline::ProgressEvent::Kind::Note);
    };
    try {
      domain = tspline::validate_domain(tspline::Domain{input_domain.outer, input_domain.holes}, how);
    } catch (const tspline::InputError&) {
      report_notes();  // what was cleaned before the ring that stopped the run
      throw;
    }
    report_notes();
  }
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
  report["input_cleaning"] = {{"notes", cleaning_notes}};
  tspline::io::write_multipatch_outputs(R, out_dir, report, samples);
  progress.settle();
  const auto& totals = report["totals"];
  progress.event({{"event", "result"},
                  {"valid", R.valid()},
                  {"certified_valid", R.certified_valid()},
                  {"patches", R.patches.size()},
                  {"cells", totals["cells"]},
                  {"min_mean_ratio_jacobian", R.min_mean_ratio_gauss()},
                  {"max_interface_gap", R.max_gap()},
                  {"out", out_dir}});
  if (progress.human()) {
    std::ostringstream s;
    s << R.patches.size() << " patches, " << R.layout.cuts.size() << " cuts, " << totals["cells"] << " cells, "
      << totals["bezier_elements"] << " elements; certified " << (R.certified_valid() ? "valid" : "NOT valid")
      << " (det J >= " << R.min_relative_det_bound() << " x element mean), min J_r " << R.min_mean_ratio_dense()
      << " (whole map); area " << R.map_area << " vs " << R.domain_area << "; largest interface gap " << R.max_gap()
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
