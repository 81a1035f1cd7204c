#pragma once
// The "layout" section of report.json: which layout the run chose and why,
// the statistics of an automatic quad layout and, where auto rejected one
// patch, the whole-map figures of that first try.
#include <nlohmann/json.hpp>

#include "tspline/pipeline/domain_parameterization.h"

namespace tspline::io {

/// {"chosen", "reason"} and, where present, "explanation" (the cuts of a
/// multi-patch map), "quad" (QuadLayoutStats, keys as the field names) and
/// "single_patch_first_try" (its dense-sample minima).
nlohmann::json layout_report(const DomainParameterization& result);

}  // namespace tspline::io
