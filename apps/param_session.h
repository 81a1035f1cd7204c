#pragma once
// A run of `tspline param` without its printing: the domain as read, cleaned
// and parameterized with the layout chosen (tspline::parameterize_domain),
// report.json and the output files. The program (cmd_param.cpp) and the Python
// module (tspline.parameterize, Map.save) both run the domain through these,
// so that the same options on the same domain give the same map and files.
#include <chrono>
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "param_options.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/pipeline/domain_parameterization.h"

namespace tspline_app {

/// A single-patch adaptive round, kept for adapt.pvd.
struct ParamIteration {
  int iteration = 0;
  tspline::TSplineMap map;
  std::vector<tspline::CellMapQuality> cells;
};

struct ParamRun {
  std::string source;                       ///< what report.json calls the input (its path, or "array", ...)
  tspline::io::DomainInput domain;          ///< as read (description: format, CRS, projection, holes)
  std::vector<std::string> cleaning_notes;  ///< what the cleaning of the rings removed (domains with holes)
  tspline::DomainParameterization result;
  std::vector<ParamIteration> iterations;  ///< the single patch's adaptive rounds (empty for several patches)
  ParamSettings settings;                  ///< as run (without the progress callback)
  double seconds = 0.0;
  nlohmann::json report;  ///< report.json

  bool multipatch() const { return result.patches.has_value(); }
  /// The maps: one, or one per patch.
  std::vector<const tspline::TSplineMap*> maps() const;
  bool certified_valid() const;
};

/// What the program shows while a run works (all may be empty).
struct ParamHooks {
  tspline::ProgressCallback progress;
  /// A single-patch adaptive round: (iteration, cells, functions).
  std::function<void(int, std::size_t, std::size_t)> on_iteration;
  tspline::PatchCallback on_patch;
};

/// A previous map of the same boundary before it moved (warm start: --from,
/// Map.deform): its patches' maps, polygons and corners, and for a layout its
/// interfaces, cuts and rings.
struct PreviousMap {
  std::vector<const tspline::TSplineMap*> maps;     ///< one per patch
  std::vector<tspline::io::TSplineFileMeta> metas;  ///< per patch: its polygon and corners
  bool layout = false;                              ///< a multi-patch map (format version 2)
  std::vector<tspline::Interface> interfaces;       ///< layout: as in its file
  std::vector<tspline::Cut> cuts;
  std::optional<tspline::Domain> domain;  ///< layout: the rings it was built on (the file's "domain")
  std::string name;                       ///< for messages: the file, or "the previous map"
};

/// Runs `tspline param` on a domain: corners and cuts checked against the
/// layout, the rings of a domain with holes cleaned with the run's boundary
/// tolerance, parameterize_domain, report.json. `started`: when the run began
/// (report.json's seconds count from there, reading the file included).
/// With `previous` (or settings.from_file), the map of the moved boundary
/// from that map (tspline::reparameterize) instead of parameterize_domain.
/// \throw tspline::InputError for invalid domains or options (--corners with
/// several patches, --cuts); as parameterize_domain otherwise.
ParamRun run_param(tspline::io::DomainInput domain, std::string source, const ParamSettings& settings,
                   const ParamHooks& hooks = {},
                   std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now(),
                   std::optional<PreviousMap> previous = std::nullopt);

/// The files `tspline param` writes (output_files.h), for a single patch or
/// several, into out_dir (created if missing), each atomically, report.json last.
/// \throw tspline::IoError.
void write_param_run(const ParamRun& run, const std::string& out_dir);

/// The names of those files, in the order of the program's summary line.
std::vector<std::string> param_run_files(const ParamRun& run);

}  // namespace tspline_app
