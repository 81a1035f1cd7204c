// `tspline param`: the parameterization of a domain (polygon or GIS layer; with
// holes, one map per four-sided patch) and its output folder.
#include <CLI/CLI.hpp>
#include <array>
#include <chrono>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "commands.h"
#include "kept_until_exit.h"
#include "param_multipatch.h"
#include "param_options_cli.h"
#include "param_session.h"
#include "progress.h"
#include "toolkit/io/atomic_file.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/param_output.h"

namespace tspline_app {
namespace {

int param_command(const std::string& input, const std::string& out_dir, const ParamSettings& settings,
                  tspline_app::OutputMode mode) {
  tspline_app::Progress progress(mode);
  const bool quiet = mode != tspline_app::OutputMode::Human;
  // Fail on an unwritable output directory before any computation.
  toolkit::io::ensure_writable_directory(out_dir);
  const auto t0 = std::chrono::steady_clock::now();
  ParamHooks hooks;
  hooks.progress = [&progress](const tspline::ProgressEvent& e) { progress.report(e); };
  hooks.on_iteration = [&](int it, std::size_t cells, std::size_t functions) {
    progress.event({{"event", "iteration"}, {"iteration", it}, {"cells", cells}, {"functions", functions}});
    progress.progress("adaptive rounds", it + 1, settings.adaptive.max_adapt + 1);
  };
  hooks.on_patch = [&](std::size_t p, int round) {
    progress.event({{"event", "patch"}, {"patch", p}, {"round", round}});
  };
  const KeptUntilExit<ParamRun> kept(
      tspline_app::run_param(tspline::io::read_domain(input, settings.domain), input, settings, hooks, t0));
  const ParamRun& run = *kept;
  const tspline::AdaptiveOptions& adaptive = settings.adaptive;
  if (run.multipatch()) return tspline_app::write_multipatch_param(run, out_dir, progress);
  const tspline::ParameterizationResult& result = *run.result.single;
  write_param_run(run, out_dir);
  const nlohmann::json& report = run.report;
  progress.settle();
  const std::vector<std::string> files = param_run_files(run);
  std::string file_list;
  for (const std::string& f : files) file_list += (file_list.empty() ? "" : ", ") + f;
  progress.event({{"event", "result"},
                  {"valid", result.valid()},
                  {"good", result.good()},
                  {"certified_valid", result.certified_valid()},
                  {"min_mean_ratio_jacobian", result.quality.min_mean_ratio},
                  {"whole_map",
                   {{"mean_ratio", report["jacobian"]["whole_map"].value("mean_ratio", nlohmann::json())},
                    {"scaled_jacobian", report["jacobian"]["whole_map"].value("scaled_jacobian", nlohmann::json())}}},
                  {"cells", result.map ? result.map->mesh().num_cells() : 0},
                  {"stop_reason", result.stop_reason},
                  {"out", out_dir},
                  {"files", files}});
  if (!quiet) {
    std::cout << tspline::io::whole_map_quality_summary(report["jacobian"]["whole_map"])
              << "; at the Gauss points min J_r " << result.quality.min_mean_ratio << std::endl;
    std::cout << "wrote " << file_list << " to " << out_dir << std::endl;
  }
  if (!result.valid()) {
    std::cerr << "tspline: error: the map is not valid: det J <= 0 at " << result.quality.nonpositive_det << " of "
              << result.quality.points << " quadrature points; adaptive refinement stopped: " << with_option_names(result.stop_reason, Spelling::Cli)
              << " (files written; see surface.vtu, point data det_jacobian, or `tspline render OUTDIR`); try "
                 "other --corners, a smaller --tol-rel, or more --max-adapt rounds"
              << std::endl;
    return 3;
  }
  if (adaptive.certify && !result.certified_valid()) {
    const tspline::MapCertification& c = result.certification;
    std::string where;
    if (!c.failures.empty()) {
      // Where: the first failing element, in parametric and physical coordinates.
      const tspline::CertificationFailure& f = c.failures.front();
      const Eigen::Vector2d uv = f.certificate.status == tspline::ElementStatus::Invalid
                                     ? f.certificate.negative_at
                                     : Eigen::Vector2d(0.5 * (f.lo + f.hi));
      const Eigen::Vector2d x = result.map->point(uv);
      std::ostringstream s;
      s << ", e.g. near (" << x.x() << ", " << x.y() << ") = S(" << uv.x() << ", " << uv.y() << ")";
      where = s.str();
    }
    std::cerr << "tspline: error: the map is not certified valid: " << c.elements - c.certified << " of " << c.elements
              << " elements not certified (" << c.invalid << " with det J < 0 proven, " << c.undecided
              << " undecided" << where << "); adaptive refinement stopped: " << with_option_names(result.stop_reason, Spelling::Cli)
              << " (files written; run 'tspline check' on tspline.json for the elements)" << std::endl;
    return 3;
  }
  if (!result.good() && !quiet)
    std::cout << "warning: min J_r " << result.quality.min_mean_ratio << " is below --min-jacobian "
              << adaptive.min_jacobian << "; adaptive refinement stopped: " << with_option_names(result.stop_reason, Spelling::Cli)
              << " (the corner choice fixes the map's aspect ratio: try other --corners)" << std::endl;
  return 0;
}

/// What `tspline param` takes besides the table's options.
struct ParamArgs {
  std::string input, out_dir;
  bool quiet = false, json_events = false;
};

}  // namespace

void add_param_command(CLI::App& app, CommandAction& action) {
  const Subcommand<ParamArgs> param_sub = add_subcommand<ParamArgs>(
      app, "param",
      "Parameterize the domain bounded by a polygon: adapted T-mesh, Coons start, untangling and smoothing, "
      "cubic T-spline fit, Jacobian check and adaptive refinement");
  CLI::App* const param = param_sub.cmd;
  const std::shared_ptr<ParamArgs> args = param_sub.args;
  param
      ->add_option(
          "DOMAIN", args->input,
          "Domain file: text polygon ('x y' per line, '#' comments, planar) or any polygon layer GDAL reads "
          "(Shapefile, GeoPackage, KML, GML, GeoJSON, ...; longitude/latitude are projected to metres)")
      ->required();
  param->add_option("--out", args->out_dir, "Output directory (created if missing)")->required();
  auto settings = std::make_shared<ParamSettings>();
  add_param_options(*param, settings);  // the table shared with the Python module (param_options.h)
  param->add_flag("--quiet,-q", args->quiet, "Print errors only");
  param->add_flag("--json", args->json_events,
                  "Print progress and the result as JSON lines (one object per line: events log, progress, "
                  "iteration, result) instead of text");
  param->callback([&action, args, settings] {
    action = [args, settings] {
      return param_command(args->input, args->out_dir, *settings,
                           output_mode(args->quiet, args->json_events));
    };
  });
}

}  // namespace tspline_app
