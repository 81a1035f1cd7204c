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
#include "param_multipatch.h"
#include "progress.h"
#include "toolkit/io/atomic_file.h"
#include "tspline/boundary/domain.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/output_files.h"
#include "tspline/io/param_output.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/pipeline/domain_parameterization.h"
#include "tspline/pipeline/parameterization.h"

namespace tspline_app {
namespace {

std::array<long long, 4> parse_corners(const std::string& text) {
  std::array<long long, 4> out{};
  std::stringstream ss(text);
  std::string item;
  int n = 0;
  while (std::getline(ss, item, ',')) {
    if (n == 4) throw tspline::InputError("--corners expects 4 comma-separated indices, got '" + text + "'");
    std::size_t used = 0;
    try {
      out[n] = std::stoll(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size())
      throw tspline::InputError("--corners: '" + item + "' is not an integer vertex index");
    ++n;
  }
  if (n != 4) throw tspline::InputError("--corners expects 4 comma-separated indices, got '" + text + "'");
  return out;
}

int run_param(const std::string& input, const std::string& out_dir, const std::string& corners_text,
              tspline::ParameterizationOptions opt, const tspline::AdaptiveOptions& adaptive, int samples,
              const tspline::io::DomainReadOptions& domain_options, tspline_app::OutputMode mode,
              const std::string& cuts_file, const std::string& layout_name, bool init_level_given) {
  if (!corners_text.empty()) opt.corners = parse_corners(corners_text);
  if (samples < 1 || samples > 64) throw tspline::InputError("--samples must be in [1, 64]");
  tspline::DomainParameterizationOptions choice;
  choice.layout = tspline::parse_layout_mode(layout_name);
  if (init_level_given) choice.patch_initial_level = opt.initial_level;  // else the layout's own default
  tspline_app::Progress progress(mode);
  const bool quiet = mode != tspline_app::OutputMode::Human;
  opt.progress = [&progress](const tspline::ProgressEvent& e) { progress.report(e); };
  // Fail on an unwritable output directory before any computation.
  toolkit::io::ensure_writable_directory(out_dir);
  const auto t0 = std::chrono::steady_clock::now();
  const tspline::io::DomainInput domain = tspline::io::read_domain(input, domain_options);
  if (!cuts_file.empty()) {
    choice.cuts.emplace();
    for (const tspline::Polygon& p : tspline::io::read_text_rings(cuts_file)) choice.cuts->push_back(p.vertices);
  }
  const bool several = !domain.holes.empty() || choice.cuts || choice.layout == tspline::LayoutMode::Quad;
  if (opt.corners && several)
    throw tspline::InputError("--corners applies to a single patch; a layout of several patches has its corners "
                              "at the patch corners (use --layout single on a domain without holes)");
  // A domain with holes: every ring is cleaned here with the run's boundary
  // tolerance (needles narrower than epsilon / diagonal go, one note per
  // cleaned ring); the pipeline's own validate_domain then finds nothing more.
  // (One ring is cleaned by the single-patch pipeline itself.)
  std::vector<std::string> cleaning_notes;
  tspline::Domain input_rings{domain.outer, domain.holes};
  if (!domain.holes.empty()) {
    tspline::DomainCleaningOptions how;
    how.needle_width = tspline::needle_width_for_ring(domain.outer, opt.tolerance_absolute, opt.tolerance_relative);
    how.notes = &cleaning_notes;
    auto report_notes = [&] {
      for (const std::string& note : cleaning_notes)
        tspline::report_step(opt.progress, "cleaning", "note: " + note, -1, tspline::ProgressEvent::Kind::Note);
    };
    try {
      input_rings = tspline::validate_domain(input_rings, how);
    } catch (const tspline::InputError&) {
      report_notes();  // what was cleaned before the ring that stopped the run
      throw;
    }
    report_notes();
  }
  // The single-patch iterations, kept until the layout is chosen (auto may drop them).
  struct Snapshot {
    int iteration;
    tspline::TSplineMap map;
    std::vector<tspline::CellMapQuality> cells;
  };
  std::vector<Snapshot> snapshots;
  const tspline::DomainParameterization P = tspline::parameterize_domain(
      input_rings, opt, adaptive, choice,
      [&](int it, const tspline::TMesh& mesh, const std::vector<Eigen::Vector2d>&, const tspline::TSplineMap& map,
          const std::vector<tspline::CellMapQuality>& cells) {
        if (it == 0) snapshots.clear();  // a new run (auto's first try was run again, or dropped)
        snapshots.push_back({it, map, cells});
        progress.event({{"event", "iteration"},
                        {"iteration", it},
                        {"cells", mesh.num_cells()},
                        {"functions", map.basis().size()}});
        progress.progress("adaptive rounds", it + 1, adaptive.max_adapt + 1);
      },
      [&](std::size_t p, int round) { progress.event({{"event", "patch"}, {"patch", p}, {"round", round}}); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (P.patches)
    return tspline_app::write_multipatch_param(P, domain, input, out_dir, adaptive, samples, seconds, progress,
                                               cleaning_notes);
  const tspline::ParameterizationResult& result = *P.single;
  tspline::io::AdaptSeriesWriter series(out_dir, samples);
  for (const Snapshot& s : snapshots) series.add(s.iteration, s.map, &s.cells);
  series.finish();
  nlohmann::json report = tspline::io::param_report(result, input);
  report["input_geometry"] = domain.description;  // format, layer, CRS, projection (gis_reader.h)
  report["layout"] = {{"chosen", P.layout}, {"reason", P.reason}};
  tspline::io::write_param_outputs(result, out_dir, report, samples);
  progress.settle();
  std::vector<std::string> files;
  std::string file_list;
  for (const std::string_view f : tspline::io::output_files::kParam) {
    files.emplace_back(f);
    file_list += (file_list.empty() ? "" : ", ") + files.back();
  }
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
              << result.quality.points << " quadrature points; adaptive refinement stopped: " << result.stop_reason
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
              << " undecided" << where << "); adaptive refinement stopped: " << result.stop_reason
              << " (files written; run 'tspline check' on tspline.json for the elements)" << std::endl;
    return 3;
  }
  if (!result.good() && !quiet)
    std::cout << "warning: min J_r " << result.quality.min_mean_ratio << " is below --min-jacobian "
              << adaptive.min_jacobian << "; adaptive refinement stopped: " << result.stop_reason
              << " (the corner choice fixes the map's aspect ratio: try other --corners)" << std::endl;
  return 0;
}


/// The options of `tspline param` as parsed (they live as long as the program).
struct ParamArgs {
  std::string input, out_dir, corners, cuts_file, layer, layout = "auto";
  tspline::ParameterizationOptions opt;
  tspline::AdaptiveOptions adaptive;
  tspline::io::DomainReadOptions domain_options;
  double tol = 0.0;
  std::size_t geojson_polygon = 0, feature = 0;
  int samples = 4;
  bool quiet = false, json_events = false, no_cpo = false;
  std::string optimizer = "lbfgs";
};

}  // namespace

void add_param_command(CLI::App& app, CommandAction& action) {
  auto args = std::make_shared<ParamArgs>();
  ParamArgs& A = *args;
  CLI::App* param = app.add_subcommand(
      "param", "Parameterize the domain bounded by a polygon: adapted T-mesh, Coons start, untangling and smoothing, "
      "cubic T-spline fit, Jacobian check and adaptive refinement");
  param->add_option("DOMAIN", A.input,
                    "Domain file: text polygon ('x y' per line, '#' comments, planar) or any polygon layer GDAL reads "
                    "(Shapefile, GeoPackage, KML, GML, GeoJSON, ...; longitude/latitude are projected to metres)")
      ->required();
  param->add_option("--out", A.out_dir, "Output directory (created if missing)")->required();
  param->add_option("--layout", A.layout,
                    "auto: one patch where a first try is certified and good over the whole map (scaled Jacobian "
                    ">= 0.3, J_r >= 0.1), an automatic quad layout otherwise and always for domains with holes; "
                    "single: one patch (no holes); quad: the automatic quad layout")
      ->check(CLI::IsMember({"auto", "single", "quad"}))
      ->capture_default_str();
  param->add_option("--cuts", A.cuts_file,
                    "The layout given by hand: cuts into four-sided patches as polylines ('x y' per line, cuts "
                    "separated by blank lines; ends on rings or at ends of other cuts); default: --layout");
  param->add_option("--corners", A.corners,
                    "Four vertex indices i,j,k,l (0-based, the file's own numbering, in cyclic file order) "
                    "mapped to (0,0),(1,0),(1,1),(0,1); default: automatic choice explained in report.json");
  param->add_option("--corner-trials", A.opt.corner_trials,
                    "Automatic corners: run this many of the best choices and keep the one with the fewest "
                    "inverted cells, then the best min + mean quality (1: no trials)")
      ->capture_default_str();
  auto* tol_opt = param->add_option("--tol", A.tol,
                                    "Boundary tolerance epsilon as an absolute AREA (units^2): a boundary cell "
                                    "is refined while a polygon vertex forms with its edge a triangle larger "
                                    "than epsilon (Brovka 2013 Sect. 3)");
  param->add_option("--tol-rel", A.opt.tolerance_relative,
                    "Boundary tolerance relative to the squared bounding-box diagonal, used when --tol is "
                    "not given")
      ->capture_default_str();
  auto* init_opt = param->add_option("--init-level", A.opt.initial_level,
                                     "Initial uniform level L in [0, 10]: 2^L x 2^L cells (patches of a quad "
                                     "layout: 2 unless given)")
      ->capture_default_str();
  param->add_option("--max-level", A.opt.max_level, "Maximum refinement level of any cell")->capture_default_str();
  param->add_option("--max-sweeps", A.opt.smoothing.max_sweeps, "Maximum Gauss-Seidel sweeps of the optimization")
      ->capture_default_str();
  param->add_option("--omega", A.opt.smoothing.over_relaxation,
                    "Over-relaxation factor in [1, 2) of the node updates (1: plain Gauss-Seidel)")
      ->capture_default_str();
  param->add_option("--sweep-tol", A.opt.smoothing.relative_displacement_tolerance,
                    "Stop when the largest node move relative to its local edge length is below this")
      ->capture_default_str();
  auto* gj_opt = param->add_option("--polygon", A.geojson_polygon,
                                   "GIS file (or GeoJSON) with several polygons (in the layer or the --feature): "
                                   "which one (0-based, file order); default the largest");
  auto* layer_opt = param->add_option("--layer", A.layer, "GIS file: layer name or 0-based index; default the first "
                                                        "layer with polygons");
  auto* feature_opt = param->add_option("--feature", A.feature, "GIS file: only this feature (0-based, layer order)");
  param->add_flag("--planar", A.domain_options.planar,
                  "Keep the coordinates as they are (no projection of longitude/latitude to metres)");
  param->add_option("--min-jacobian", A.adaptive.min_jacobian,
                    "delta of Sect. 6.2: refine the cells where the mean ratio Jacobian J_r = 2 det J / |J|^2 is "
                    "below it at some of the 4x4 Gauss points")
      ->capture_default_str();
  param->add_option("--max-adapt", A.adaptive.max_adapt, "Adaptive refinement rounds at most")->capture_default_str();
  param->add_option("--max-cells", A.adaptive.max_cells, "The T-mesh never goes beyond this many cells (boundary refinement, repair, adaptive "
                    "refinement); a polygon that needs more stops with a message")
      ->capture_default_str();
  param->add_flag("--no-control-point-optimization", A.no_cpo,
                  "Keep the interpolating map of the T-mesh (by default all interior control points are "
                  "untangled and smoothed globally until det J > 0 is certified)");
  param->add_option("--optimizer", A.optimizer,
                    "Minimizer of the control-point untangling and smoothing: 'lbfgs' (L-BFGS, curvature kept "
                    "across the eps stages) or 'newton' (projected Newton, Cholesky or conjugate gradients: fewer "
                    "iterations and a higher min J_r, each iteration a Hessian assembly; slower on the benchmarks)")
      ->check(CLI::IsMember({"newton", "lbfgs"}))
      ->capture_default_str();
  param->add_option("--cert-depth", A.adaptive.certification.max_depth,
                    "Certification of det J > 0 on every Bezier element: de Casteljau subdivision levels at most "
                    "(an element still undecided there is refined like one with J_r below --min-jacobian)")
      ->check(CLI::Range(0, 20))
      ->capture_default_str();
  param->add_option("--samples", A.samples, "surface.vtu: k x k sub-quads per T-mesh cell")->capture_default_str();
  param->add_flag("--quiet,-q", A.quiet, "Print errors only");
  param->add_flag("--json", A.json_events,
                  "Print progress and the result as JSON lines (one object per line: events log, progress, "
                  "iteration, result) instead of text");
  param->callback([&action, tol_opt, gj_opt, layer_opt, feature_opt, init_opt, args] {
    action = [tol_opt, gj_opt, layer_opt, feature_opt, init_opt, args] {
      ParamArgs& A = *args;
      if (tol_opt->count() > 0) A.opt.tolerance_absolute = A.tol;
      A.adaptive.optimize_control_points = !A.no_cpo;
      A.adaptive.untangling.optimizer =
          A.optimizer == "lbfgs" ? tspline::MapOptimizer::LBFGS : tspline::MapOptimizer::Newton;
      A.opt.max_cells = A.adaptive.max_cells;  // one budget for the front half and the adaptive loop
      if (gj_opt->count() > 0) A.domain_options.polygon_index = A.geojson_polygon;
      if (layer_opt->count() > 0) A.domain_options.layer = A.layer;
      if (feature_opt->count() > 0) A.domain_options.feature = A.feature;
      return run_param(A.input, A.out_dir, A.corners, A.opt, A.adaptive, A.samples, A.domain_options,
                       tspline_app::output_mode(A.quiet, A.json_events), A.cuts_file, A.layout,
                       init_opt->count() > 0);
    };
  });
}

}  // namespace tspline_app
