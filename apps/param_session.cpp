#include "param_session.h"

#include <cmath>
#include <string_view>

#include "toolkit/io/atomic_file.h"
#include "tspline/boundary/domain.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/deform/layout_reparameterization.h"
#include "tspline/deform/reparameterization.h"
#include "tspline/errors.h"
#include "tspline/io/layout_output.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/output_files.h"
#include "tspline/io/param_output.h"
#include "tspline/io/polygon_reader.h"
#include "toolkit/timing.h"

namespace tspline_app {
namespace {

using nlohmann::json;

/// report.json of a multi-patch run: the multi-patch report with the input,
/// cleaning and layout sections.
json multipatch_report(const ParamRun& run) {
  const tspline::DomainParameterization& P = run.result;
  const tspline::MultiPatchResult& R = *P.patches;
  json report = tspline::io::multipatch_report(R, run.source, run.seconds);
  report["input_geometry"] = run.domain.description;
  report["input_cleaning"] = {{"notes", run.cleaning_notes}};
  report["layout"] = tspline::io::layout_report(P);
  return report;
}

json single_report(const ParamRun& run) {
  json report = tspline::io::param_report(*run.result.single, run.source);
  report["input_geometry"] = run.domain.description;  // format, layer, CRS, projection (gis_reader.h)
  // What the session cleaned before the pipeline (sharp tips cut off, needles
  // removed), then what the pipeline's own cleaning found.
  if (!run.cleaning_notes.empty()) {
    nlohmann::json& notes = report["input_cleaning"]["notes"];
    nlohmann::json all = run.cleaning_notes;
    if (notes.is_array())
      for (const auto& n : notes) all.push_back(n);
    notes = std::move(all);
  }
  report["layout"] = tspline::io::layout_report(run.result);
  return report;
}

/// The map of a moved boundary from the previous map (--from, Map.deform).
/// `read`: the rings as read (every vertex, the file's numbering).
tspline::DomainParameterization warm_start(const PreviousMap& prev, const tspline::io::DomainInput& read,
                                           const tspline::ParameterizationOptions& opt,
                                           const tspline::AdaptiveOptions& adaptive, ParamRun& run,
                                           const ParamHooks& hooks) {
  if (opt.corners) throw tspline::InputError("--corners with --from: the corners are the previous map's");
  tspline::DomainParameterization out;
  out.reason = "warm start from the previous map " + prev.name;
  if (prev.layout) {
    if (!prev.domain)
      throw tspline::InputError(prev.name + ": the file does not record the rings of its domain (written by an older "
                                "version); map the domain from scratch once, then warm-start from that map");
    const std::size_t rings = prev.domain->holes.size() + 1;
    if (read.holes.size() + 1 != rings)
      throw tspline::InputError(prev.name + ": the previous map's domain has " + std::to_string(rings) +
                                " rings, the moved domain " + std::to_string(read.holes.size() + 1) +
                                " (ring k moves to ring k)");
    tspline::PreviousLayout old;
    old.domain = *prev.domain;
    old.maps = prev.maps;
    for (const tspline::io::TSplineFileMeta& m : prev.metas) {
      old.polygons.push_back(m.boundary);
      old.corners.push_back(m.corners);
    }
    old.interfaces = prev.interfaces;
    old.cuts = prev.cuts;
    tspline::Domain moved;
    moved.outer = tspline::corresponding_polygon(prev.domain->outer, read.outer, tspline::ring_name(0));
    for (std::size_t h = 0; h < read.holes.size(); ++h)
      moved.holes.push_back(
          tspline::corresponding_polygon(prev.domain->holes[h], read.holes[h], tspline::ring_name(h + 1)));
    out.layout = "quad";
    out.patches = tspline::reparameterize_layout(old, moved, opt, adaptive, {}, hooks.on_patch);
    return out;
  }
  if (!read.holes.empty())
    throw tspline::InputError(prev.name + ": the previous map has one ring, the moved domain " +
                              std::to_string(read.holes.size() + 1) + " (rings must correspond one to one)");
  const tspline::io::TSplineFileMeta& meta = prev.metas.front();
  const tspline::Polygon moved = tspline::corresponding_polygon(meta.boundary, read.outer, tspline::ring_name(0));
  out.layout = "single";
  out.single = tspline::reparameterize(
      *prev.maps.front(), meta.boundary, meta.corners, moved, opt, adaptive, std::nullopt,
      [&](int it, const tspline::TMesh& mesh, const std::vector<Eigen::Vector2d>&, const tspline::TSplineMap& map,
          const std::vector<tspline::CellMapQuality>& cells) {
        run.iterations.push_back({it, map, cells});
        if (hooks.on_iteration) hooks.on_iteration(it, mesh.num_cells(), map.basis().size());
      });
  return out;
}

}  // namespace

std::vector<const tspline::TSplineMap*> ParamRun::maps() const {
  std::vector<const tspline::TSplineMap*> out;
  if (result.patches)
    for (const tspline::ParameterizationResult& r : result.patches->patches) out.push_back(&*r.map);
  else if (result.single && result.single->map)
    out.push_back(&*result.single->map);
  return out;
}

bool ParamRun::certified_valid() const {
  return result.patches ? result.patches->certified_valid()
                        : result.single && result.single->certified_valid();
}

ParamRun run_param(tspline::io::DomainInput domain, std::string source, const ParamSettings& settings,
                   const ParamHooks& hooks, std::chrono::steady_clock::time_point started,
                   std::optional<PreviousMap> previous) {
  ParamRun run;
  run.source = std::move(source);
  run.domain = std::move(domain);
  run.settings = settings;
  tspline::ParameterizationOptions opt = settings.opt;
  opt.progress = hooks.progress;
  tspline::DomainParameterizationOptions choice = settings.choice;
  if (!settings.cuts_file.empty()) {
    choice.cuts.emplace();
    for (const tspline::Polygon& p : tspline::io::read_text_rings(settings.cuts_file))
      choice.cuts->push_back(p.vertices);
  }
  const tspline::io::DomainInput& in = run.domain;
  const bool several = !in.holes.empty() || choice.cuts || choice.layout == tspline::LayoutMode::Quad;
  if (opt.corners && several)
    throw tspline::InputError(
        "--corners applies to a single patch; a layout of several patches has its corners "
        "at the patch corners (use --layout single on a domain without holes)");
  // A domain with holes: every ring is cleaned here with the run's boundary
  // tolerance (needles narrower than epsilon / diagonal go, one note per
  // cleaned ring); the pipeline's own validate_domain then finds nothing more.
  // (One ring is cleaned by the single-patch pipeline itself.)
  tspline::Domain rings{in.outer, in.holes};
  // Sharp tips are cut off here too (one ring or several), except for a warm
  // start, whose vertices must match the previous map's one to one.
  const bool blunt = settings.blunt_tips_degrees > 0.0 && !previous && settings.from_file.empty();
  if (!in.holes.empty() || blunt) {
    tspline::DomainCleaningOptions how;
    const double width = tspline::needle_width_for_ring(in.outer, opt.tolerance_absolute, opt.tolerance_relative);
    how.needle_width = width;
    how.notes = &run.cleaning_notes;
    // The tolerance's area epsilon on the ring's diagonal as the needle width
    // measures it (width = r d): a typo vertex 4e9 km out must not make every
    // tip and islet "below the tolerance".
    how.crossing_repair_area = opt.tolerance_absolute ? *opt.tolerance_absolute
                               : opt.tolerance_relative > 0.0 && std::isfinite(width)
                                   ? width * width / opt.tolerance_relative
                                   : 0.0;
    how.repair_crossing_holes = settings.repair_crossing_holes;
    if (blunt) how.blunt_tips_below_degrees = settings.blunt_tips_degrees;
    auto report_notes = [&] {
      for (const std::string& note : run.cleaning_notes)
        tspline::report_step(opt.progress, "cleaning", "note: " + note, -1,
                             tspline::ProgressEvent::Kind::Note);
    };
    if (in.holes.empty()) {
      // One ring: the single-patch pipeline cleans and validates it itself
      // (its messages and report); here only its sharp tips are cut, and the
      // ring cleaned here goes on only if some were.
      std::size_t tips = 0;
      how.blunted_tips = &tips;
      try {
        tspline::Domain blunted = tspline::validate_domain(rings, how);
        if (tips > 0) rings = std::move(blunted);
        else run.cleaning_notes.clear();
      } catch (const tspline::InputError&) {
        run.cleaning_notes.clear();  // the pipeline names the problem
      }
    } else {
      try {
        rings = tspline::validate_domain(rings, how);
      } catch (const tspline::InputError&) {
        report_notes();  // what was cleaned before the ring that stopped the run
        throw;
      }
    }
    report_notes();
  }
  std::optional<tspline::io::LoadedMaps> file;
  if ((previous || !settings.from_file.empty()) &&
      (!settings.cuts_file.empty() || settings.choice.layout != tspline::LayoutMode::Auto))
    throw tspline::InputError("--layout or --cuts with --from: the layout is the previous map's");
  if (!previous && !settings.from_file.empty()) {
    file = tspline::io::read_maps_file(settings.from_file);
    previous.emplace();
    for (const tspline::io::LoadedTSpline& t : file->patches) {
      previous->maps.push_back(&t.map);
      previous->metas.push_back(t.meta);
    }
    previous->layout = file->version != 1;
    previous->interfaces = file->interfaces;
    previous->cuts = file->cuts;
    previous->domain = file->domain;
    previous->name = settings.from_file;
  }
  if (previous) {
    run.result = warm_start(*previous, run.domain, opt, settings.adaptive, run, hooks);
  } else {
    run.result = tspline::parameterize_domain(
      rings, opt, settings.adaptive, choice,
      [&](int it, const tspline::TMesh& mesh, const std::vector<Eigen::Vector2d>&,
          const tspline::TSplineMap& map, const std::vector<tspline::CellMapQuality>& cells) {
        if (it == 0) run.iterations.clear();  // a new run (auto's first try was run again, or dropped)
        run.iterations.push_back({it, map, cells});
        if (hooks.on_iteration) hooks.on_iteration(it, mesh.num_cells(), map.basis().size());
      },
      hooks.on_patch);
  }
  if (run.result.patches) run.iterations.clear();  // adapt.pvd is written for a single patch only
  run.seconds = toolkit::seconds_since(started);
  if (run.result.patches)  // (seconds on a large layout: the user is told)
    tspline::report_step(opt.progress, "report",
                         "report: certified bounds of J_r and the scaled Jacobian on every Bezier element of " +
                             std::to_string(run.result.patches->patches.size()) + " patches");
  run.report = run.result.patches ? multipatch_report(run) : single_report(run);
  // The run's options by `tspline param`'s names (Python's with '_' for '-'),
  // every option of the table: what a rerun needs.
  run.report["options"] = settings_json(run.settings);
  return run;
}

void write_param_run(const ParamRun& run, const std::string& out_dir) {
  toolkit::io::ensure_writable_directory(out_dir);
  const int samples = run.settings.samples;
  const toolkit::io::VtuCompression compression = run.settings.vtu_compression;
  if (run.result.patches) {
    tspline::io::write_multipatch_outputs(*run.result.patches, out_dir, run.report, samples, compression);
    return;
  }
  tspline::io::AdaptSeriesWriter series(out_dir, samples, compression);
  for (const ParamIteration& s : run.iterations) series.add(s.iteration, s.map, &s.cells);
  series.finish();
  tspline::io::write_param_outputs(*run.result.single, out_dir, run.report, samples, compression);
}

std::vector<std::string> param_run_files(const ParamRun& run) {
  namespace of = tspline::io::output_files;
  std::vector<std::string> files;
  if (run.result.patches) {
    for (const std::string_view f : of::kMultipatchParam) files.emplace_back(f);
  } else {
    for (const std::string_view f : of::kParam) files.emplace_back(f);
  }
  return files;
}

}  // namespace tspline_app
