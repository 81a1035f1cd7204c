#pragma once
// `tspline param` on a multi-patch map (a domain with holes, --cuts, or a quad
// layout chosen by --layout): its outputs and summary.
#include <string>

#include "param_session.h"
#include "progress.h"

namespace tspline_app {

/// Writes the outputs of a multi-patch run (write_param_run) and prints its
/// summary; returns the exit code (0, or 3 if the map is not watertight or
/// some patch is not certified valid).
int write_multipatch_param(const ParamRun& run, const std::string& out_dir, Progress& progress);

}  // namespace tspline_app
