#pragma once
// Maps of domains with holes: the domain is cut into four-sided patches
// (patch_layout.h; automatic_cuts.h unless the cuts are given), each patch goes
// through the single-patch pipeline (run_parameterization) with its corners at
// its cut ends, and the interfaces are made conforming: the two patches along
// a cut are run with the union of their border knots on it (the same dyadic
// parameters, mirrored: the patches traverse the cut in opposite directions)
// until their boundary curves agree. Both curves are then the cubic spline
// interpolant of the same points at the same knots (tspline_fit.h: on the
// border of [0,1]^2 the map is a univariate spline determined by the border
// interpolation points alone; later refinement reproduces it exactly), so the
// two images of an interface agree to round-off.
#include <Eigen/Core>
#include <atomic>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/multipatch/patch_layout.h"
#include "tspline/pipeline/adaptive_parameterization.h"

namespace tspline {

struct MultiPatchOptions {
  /// Rounds of re-running the patches of non-conforming interfaces at most.
  int max_sync_rounds = 4;
  /// An interface conforms when its two images differ by at most this times
  /// the domain's bounding-box diagonal (sampled at the knots and between).
  double gap_tolerance = 1e-12;
  /// Patches run concurrently on this many threads (0: one per core).
  int threads = 0;
  /// Checked before each patch and each interface round: once set (by another
  /// thread), MultiPatchCancelled is thrown.
  const std::atomic<bool>* cancel = nullptr;
  /// Called after each patch's map of the first round (from the thread that
  /// ran it, so it must be thread-safe): a non-empty text stops the run. The
  /// patches not yet started are not run, and run_multipatch_parameterization
  /// throws MultiPatchStopped("patch P " + text). Lets a caller that only
  /// wants the map if every patch is good stop at the first that is not.
  /// With it, the first round runs the patches sharpest polygon corner first
  /// (the least sine of the angles at their four corners): those most likely
  /// to be below a threshold. The results do not depend on the order.
  std::function<std::string(std::size_t patch, const ParameterizationResult&)> stop_when;
};

/// Thrown where MultiPatchOptions::cancel was set.
struct MultiPatchCancelled : std::exception {
  const char* what() const noexcept override { return "the patches' run was cancelled"; }
};

/// Thrown where MultiPatchOptions::stop_when stopped the run; what() names
/// the patch and gives stop_when's text.
struct MultiPatchStopped : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct InterfaceReport {
  double max_gap = 0.0;          ///< largest distance between the two images (sampled)
  std::size_t knots_a = 0, knots_b = 0;  ///< border vertices of the two sides (both corners included)
  bool same_knots = false;       ///< the two sides carry the same knots (mirrored)
};

struct MultiPatchResult {
  Domain domain;  ///< validated
  PatchLayout layout;
  std::string cuts_explanation;  ///< automatic choice, or "given"
  std::vector<ParameterizationResult> patches;
  std::vector<InterfaceReport> interfaces;
  int sync_rounds = 0;           ///< rounds of re-running patches (0: conforming at once)
  double diameter = 0.0;         ///< bounding-box diagonal of the domain
  double domain_area = 0.0;      ///< polygon areas: outer minus holes
  double map_area = 0.0;         ///< sum over patches of the integral of det J
  double max_gap() const;
  bool conforming(double gap_tolerance) const { return max_gap() <= gap_tolerance * diameter; }
  bool valid() const;
  bool certified_valid() const;
  double min_relative_det_bound() const;  ///< min over patches of the certified relative lower bound
  double min_mean_ratio_dense() const;    ///< min over patches of J_r over the dense sample
  double min_mean_ratio_gauss() const;    ///< min over patches of J_r at Gauss points
  double min_scaled_jacobian_dense() const;  ///< min over patches of the scaled Jacobian over the dense sample
};

/// Area of the image of the map: the integral of det J over [0,1]^2, computed
/// as the integral of x dy along the image of the square's border (Green's
/// theorem; exact up to round-off: the border curve is a polynomial spline).
double map_area(const TSplineMap& map);

/// The largest distance between S_a(side_a at t) and S_b(side_b at 1 - t) over
/// 64 equal steps of t and the border knots of both sides.
double interface_gap(const TSplineMap& a, int side_a, const TSplineMap& b, int side_b);

/// Parametric point of chord parameter t on `side` (boundary_map.h orientation).
Eigen::Vector2d side_point_uv(int side, double t);

/// Called when a patch starts (patch index, round) for progress lines.
using PatchCallback = std::function<void(std::size_t patch, int round)>;

/// Runs task(i) for every i in [0, n) on min(threads, n) threads of their own
/// (each patch run uses the process's pool inside), each taking the next i;
/// after the first exception no task starts, and it is rethrown here.
void for_each_patch(std::size_t n, unsigned threads, const std::function<void(std::size_t)>& task);

/// The threads for the patches: `requested` if > 0, else the hardware's.
unsigned patch_threads(int requested);

/// `progress` called under `lock` (progress events of concurrent patches), empty if progress is.
ProgressCallback locked_progress(const ProgressCallback& progress, std::mutex& lock);

/// The progress callback of patch p: `progress` with "patch p: " before each text (empty if progress is).
ProgressCallback patch_progress(const ProgressCallback& progress, std::size_t p);

/// The last steps of a multi-patch run once every patch has its map: each
/// patch refined to the union of the knots of its interfaces (the map carried
/// over, kept only if still certified), the interfaces measured
/// (R.interfaces) and the map's area summed (R.map_area). `progress` (may be
/// empty) is told what each step did.
void finish_multipatch_result(MultiPatchResult& R, const AdaptiveOptions& adaptive, int max_level,
                              const ProgressCallback& progress = {});

/// \param cuts the cuts, or nullopt for the automatic choice.
/// \throw InputError for an invalid domain or cuts, or no automatic layout;
/// NumericalError as run_parameterization.
MultiPatchResult run_multipatch_parameterization(const Domain& domain, const std::optional<std::vector<Cut>>& cuts,
                                                 const ParameterizationOptions& options,
                                                 const AdaptiveOptions& adaptive, const MultiPatchOptions& multi = {},
                                                 const PatchCallback& on_patch = {});

/// The same on a layout already built (patch_layout.h, quad_layout.h);
/// `explanation` says how it was made, for the report.
/// \pre `domain` is validated and `layout` is a layout of it.
MultiPatchResult run_multipatch_parameterization(const Domain& domain, PatchLayout layout,
                                                 const std::string& explanation,
                                                 const ParameterizationOptions& options,
                                                 const AdaptiveOptions& adaptive, const MultiPatchOptions& multi = {},
                                                 const PatchCallback& on_patch = {});

}  // namespace tspline
