#pragma once
// `tspline param` on a domain with holes (or with --cuts): the multi-patch map.
#include <string>

#include "progress.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/io/gis_reader.h"

namespace tspline_app {

/// Runs the multi-patch parameterization and writes its outputs; returns the
/// exit code (0, or 3 if some patch is not certified valid).
int run_multipatch_param(const tspline::io::DomainInput& domain, const std::string& input, const std::string& out_dir,
                         const std::string& cuts_file, const tspline::ParameterizationOptions& options,
                         const tspline::AdaptiveOptions& adaptive, int samples, Progress& progress);

}  // namespace tspline_app
