#include "tspline/io/layout_output.h"

#include "tspline/io/param_output.h"

namespace tspline {

// The report's keys are the field names (one list, here; from_json comes with
// the macro and is unused).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(QuadLayoutStats, patches, ring_nodes, inner_nodes, inner_valence,
                                   straight_min_scaled_jacobian, straight_mean_scaled_jacobian, repair_rounds,
                                   pillowed_rings, corner_sheets, optimization_level, rotations, openings, optimization_sweeps,
                                   corner_mean_ratio, corner_scaled_jacobian, min_size, max_size, seconds)

}  // namespace tspline

namespace tspline::io {

nlohmann::json layout_report(const DomainParameterization& result) {
  nlohmann::json out = {{"chosen", result.layout}, {"reason", result.reason}};
  if (result.patches) out["explanation"] = result.patches->cuts_explanation;
  if (result.quad_stats) out["quad"] = *result.quad_stats;
  if (result.rejected_single)
    out["single_patch_first_try"] = {{"min_scaled_jacobian_dense", result.rejected_single->min_scaled},
                                     {"min_mean_ratio_dense", result.rejected_single->min_mean_ratio}};
  if (result.single_corners)
    out["single_patch_first_try"] = {
        {"stopped", "at its frozen boundary: " + result.single_stopped},
        {"corners_note",
         "J at the corners of the square is the boundary's: upper bounds of the try's whole-map minima"},
        {"corner_min_scaled_jacobian", boundary_corner_json(result.single_corners->scaled)},
        {"corner_min_mean_ratio", boundary_corner_json(result.single_corners->mean_ratio)}};
  else if (!result.single_stopped.empty())  // stopped before its first fit: no corners yet
    out["single_patch_first_try"] = {{"stopped", "after its T-mesh optimization: " + result.single_stopped}};
  return out;
}

}  // namespace tspline::io
