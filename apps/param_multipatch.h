#pragma once
// `tspline param` on a multi-patch map (a domain with holes, --cuts, or a quad
// layout chosen by --layout): its outputs and summary.
#include <string>
#include <vector>

#include "progress.h"
#include "tspline/io/gis_reader.h"
#include "tspline/pipeline/domain_parameterization.h"

namespace tspline_app {

/// Writes the outputs of a multi-patch parameterization (`P.patches`) and
/// prints its summary; returns the exit code (0, or 3 if the map is not
/// watertight or some patch is not certified valid).
int write_multipatch_param(const tspline::DomainParameterization& P, const tspline::io::DomainInput& domain,
                           const std::string& input, const std::string& out_dir,
                           const tspline::AdaptiveOptions& adaptive, int samples, double seconds, Progress& progress,
                           const std::vector<std::string>& cleaning_notes = {});

}  // namespace tspline_app
