// Every option of the parameterization is checked here, before any work, with
// a message that names the option by its field, in backquotes (`max_cells`),
// which the programs turn into their own spelling (--max-cells, max_cells=).
#include <cmath>
#include <string>

#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/errors.h"
#include "tspline/pipeline/parameterization.h"

namespace tspline {

namespace {

[[noreturn]] void fail(const std::string& what) { throw InputError(what); }

std::string str(double v) { return std::to_string(v); }

}  // namespace

void validate_options(const ParameterizationOptions& opt) {
  if (opt.initial_level < 0 || opt.initial_level > 10)  // 2^10 x 2^10 = 10^6 cells, about 1 GB
    fail("`initial_level` must be in [0, 10], got " + std::to_string(opt.initial_level));
  if (opt.max_level < std::max(1, opt.initial_level) || opt.max_level > TMesh::kMaxLevel)
    fail("`max_level` must be in [max(1, `initial_level`), " + std::to_string(TMesh::kMaxLevel) + "], got " +
         std::to_string(opt.max_level));
  if (opt.tolerance_absolute && !(*opt.tolerance_absolute > 0.0 && std::isfinite(*opt.tolerance_absolute)))
    fail("`tolerance_absolute` must be a positive finite area, got " + str(*opt.tolerance_absolute));
  if (!(opt.tolerance_relative > 0.0 && std::isfinite(opt.tolerance_relative)))
    fail("`tolerance_relative` must be a positive finite number, got " + str(opt.tolerance_relative));
  if (opt.needle_width && !(*opt.needle_width >= 0.0 && std::isfinite(*opt.needle_width)))
    fail("`needle_width` must be a finite width >= 0, got " + str(*opt.needle_width));
  if (opt.max_repair_rounds < 0)
    fail("`max_repair_rounds` must be >= 0, got " + std::to_string(opt.max_repair_rounds));
  if (opt.corner_trials < 1) fail("`corner_trials` must be >= 1, got " + std::to_string(opt.corner_trials));
  if (opt.max_cells < 1) fail("`max_cells` must be >= 1, got " + std::to_string(opt.max_cells));
  const meshopt::SmoothingOptions& s = opt.smoothing;
  if (!(s.over_relaxation >= 1.0 && s.over_relaxation < 2.0))
    fail("`smoothing.over_relaxation` must be in [1, 2), got " + str(s.over_relaxation));
  if (s.max_sweeps < 1) fail("`smoothing.max_sweeps` must be >= 1, got " + std::to_string(s.max_sweeps));
  if (!(s.relative_displacement_tolerance > 0.0) || !std::isfinite(s.relative_displacement_tolerance))
    fail("`smoothing.relative_displacement_tolerance` must be a positive finite number, got " + str(s.relative_displacement_tolerance));
}

void validate_options(const AdaptiveOptions& ad) {
  if (!(ad.min_jacobian > 0.0 && ad.min_jacobian <= 1.0))
    fail("`min_jacobian` must be in (0, 1], got " + str(ad.min_jacobian));
  if (ad.max_adapt < 0) fail("`max_adapt` must be >= 0, got " + std::to_string(ad.max_adapt));
  if (ad.polish_stages < 0 || !(ad.polish_power >= 1.0) || !std::isfinite(ad.polish_below))
    fail("`polish_stages` must be >= 0, `polish_power` >= 1 and `polish_below` finite");
  if (ad.keep_interpolant &&
      !(std::isfinite(ad.keep_interpolant->scaled_jacobian) && std::isfinite(ad.keep_interpolant->mean_ratio)))
    fail("`keep_interpolant.scaled_jacobian` and `keep_interpolant.mean_ratio` must be finite");
  if (!std::isfinite(ad.polish_skip.scaled_jacobian) || !std::isfinite(ad.polish_skip.mean_ratio))
    fail("`polish_skip.scaled_jacobian` and `polish_skip.mean_ratio` must be finite");
  if (ad.gauss < 1 || ad.gauss > 6) fail("`gauss` (Gauss points per direction) must be in [1, 6], got " +
                                         std::to_string(ad.gauss));
  if (ad.dense_samples < 1 || ad.dense_samples > 64)
    fail("`dense_samples` (per element edge) must be in [1, 64], got " + std::to_string(ad.dense_samples));
  if (ad.stall_rounds < 1) fail("`stall_rounds` must be >= 1, got " + std::to_string(ad.stall_rounds));
  if (!(ad.min_quality_gain >= 0.0 && std::isfinite(ad.min_quality_gain)))
    fail("`min_quality_gain` must be >= 0, got " + str(ad.min_quality_gain));
  if (!(ad.max_quality_fraction > 0.0)) fail("`max_quality_fraction` must be > 0, got " + str(ad.max_quality_fraction));
  if (ad.certification.max_depth < 0 || ad.certification.max_depth > 20)
    fail("`certification.max_depth` must be in [0, 20], got " + std::to_string(ad.certification.max_depth));
  if (!(ad.certification.relative_tolerance >= 0.0 && ad.certification.relative_tolerance < 1.0))
    fail("`certification.relative_tolerance` must be in [0, 1), got " + str(ad.certification.relative_tolerance));
  const MapUntanglingOptions& u = ad.untangling;
  if (u.max_stages < 1 || u.max_iterations_per_stage < 1 || u.max_iterations < 1)
    fail("`untangling.max_stages`, `untangling.max_iterations_per_stage` and `untangling.max_iterations` must be >= 1");
  if (!(u.eps_floor > 0.0) || !(u.energy_tolerance > 0.0))
    fail("`untangling.eps_floor` and `untangling.energy_tolerance` must be > 0");
  if (!(u.quality_power >= 1.0 && u.quality_power <= 16.0))
    fail("`untangling.quality_power` must be in [1, 16], got " + str(u.quality_power));
  if (!(u.min_decrease > 0.0 && u.min_decrease < 1.0))
    fail("`untangling.min_decrease` must be in (0, 1), got " + str(u.min_decrease));
  if (u.max_quality_stages < 1) fail("`untangling.max_quality_stages` must be >= 1");
  if (u.max_newton_iterations_per_stage < 1 || !(u.newton_stage_tolerance >= 0.0))
    fail("`untangling.max_newton_iterations_per_stage` must be >= 1 and `untangling.newton_stage_tolerance` >= 0");
  if (!(u.newton_min_decrease > 0.0 && u.newton_min_decrease < 1.0))
    fail("`untangling.newton_min_decrease` must be in (0, 1), got " + str(u.newton_min_decrease));
  if (!(u.newton_stalled_min_decrease > 0.0 && u.newton_stalled_min_decrease < 1.0))
    fail("`untangling.newton_stalled_min_decrease` must be in (0, 1), got " + str(u.newton_stalled_min_decrease));
  if (u.newton_after_stalled_stages < 0)
    fail("`untangling.newton_after_stalled_stages` must be >= 0, got " + std::to_string(u.newton_after_stalled_stages));
  if (!(u.newton_fast_folded_fraction > 0.0 && u.newton_fast_folded_fraction < 1.0))
    fail("`untangling.newton_fast_folded_fraction` must be in (0, 1), got " + str(u.newton_fast_folded_fraction));
  if (u.max_cg_iterations < 1 || u.newton_cholesky_below < 0)
    fail("`untangling.max_cg_iterations` must be >= 1 and `untangling.newton_cholesky_below` >= 0");
}

}  // namespace tspline
