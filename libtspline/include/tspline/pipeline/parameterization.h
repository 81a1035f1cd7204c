#pragma once
// The front half of the parameterization pipeline (Brovka 2013 Sects. 3-4):
// validated polygon -> corners -> chord-length boundary map -> adapted balanced
// T-mesh -> Coons start -> weighted K* untangling and smoothing.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "meshopt/node_smoother.h"
#include "tspline/boundary/border_knots.h"
#include "tspline/boundary/boundary_map.h"
#include "tspline/boundary/boundary_refinement.h"
#include "tspline/boundary/polygon.h"
#include "tspline/pipeline/progress_event.h"
#include "tspline/tmesh/mesh_quality.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {

struct ParameterizationOptions {
  /// Corner vertex indices in the file's own numbering; automatic if empty.
  std::optional<std::array<long long, 4>> corners;
  /// Automatic corners: how many of the best choices to try (the whole front
  /// half, initial level capped at 5) before keeping one by best_corner_trial
  /// (a trial over max_cells ranks last). 1: no trials.
  int corner_trials = 4;
  /// Boundary tolerance epsilon (an AREA, Sect. 3). If unset, epsilon =
  /// tolerance_relative * (bounding-box diagonal)^2. Each patch of a layout
  /// (run_multipatch_parameterization) takes the smaller of this and
  /// tolerance_relative * (its own bounding-box diagonal)^2.
  std::optional<double> tolerance_absolute;
  double tolerance_relative = 1e-5;
  /// Needles and spikes narrower than this are removed from the input ring
  /// (clean_polygon). Unset: the boundary tolerance's width,
  /// needle_width_for_ring(ring, tolerance_absolute, tolerance_relative).
  /// The patches of a layout take 0 (run_multipatch_parameterization): their
  /// rings were cleaned with the domain, and a patch's own width could take
  /// away one of its corners (an acute corner beside a short edge looks like
  /// a needle's tip) or a vertex of a cut that the patch across keeps.
  std::optional<double> needle_width;
  /// Initial uniform level: 2^L x 2^L cells before boundary refinement.
  int initial_level = 3;
  /// No cell is refined beyond this level.
  int max_level = 22;
  /// The T-mesh never has more cells than this, in the front half and in the
  /// adaptive loop (one budget): boundary refinement that needs more throws
  /// InputError; repair rounds that would exceed it stop (repair_stop_reason).
  std::size_t max_cells = 200000;
  /// If inverted cells remain after optimization, refine them, re-balance,
  /// re-optimize; at most this many rounds (0 disables the repair).
  int max_repair_rounds = 8;
  /// Stop the front half (FrontTangled) where the optimized T-mesh is still
  /// tangled after its nested stages, before any repair round; the final
  /// stage is looked at once it has had an intermediate stage's 100 sweeps
  /// (if not converged by then). With corner trials, only where every trial's
  /// is (a trial waits there until one is not; then all go on as they would
  /// have: meshopt::smooth_until). A run not stopped so is the run without
  /// this option, bit for bit. For callers that only want a quick answer
  /// (auto's single-patch try, domain_parameterization.h).
  bool stop_when_tangled = false;
  /// Optimize on a nested sequence of coarser T-meshes first (same final mesh,
  /// far fewer sweeps on fine meshes). false: optimize the final mesh from Coons.
  bool nested_optimization = true;
  /// Border parameters per side that must be T-mesh vertices from the first
  /// mesh on (multi-patch maps: both sides of an interface get the same knots).
  BorderParams border_params;
  /// Node optimization settings (libmeshopt).
  meshopt::SmoothingOptions smoothing;
  /// Progress events (progress_event.h); may be empty.
  ProgressCallback progress;
};

/// The needle width of a run on `ring` (ParameterizationOptions::needle_width,
/// else that of its boundary tolerance).
double run_needle_width(const Polygon& ring, const ParameterizationOptions& opt);

/// Thrown where a run was stopped on purpose (ParameterizationOptions::
/// stop_when_tangled, AdaptiveOptions::stop_when_boundary_frozen); what() is
/// why.
struct ParameterizationStopped : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The stop of ParameterizationOptions::stop_when_tangled.
struct FrontTangled : ParameterizationStopped {
  using ParameterizationStopped::ParameterizationStopped;
};

struct StageTime {
  std::string stage;
  double seconds = 0.0;
};

/// One automatic corner choice tried on a coarser T-mesh.
struct CornerTrial {
  std::array<std::size_t, 4> corners{};  ///< indices into the CCW polygon
  std::size_t inverted_cells = 0;
  double min_mean_ratio = 0.0;
  double mean_mean_ratio = 0.0;
};

/// The rule that keeps one of the corner trials: the fewest inverted cells,
/// then the highest min + mean triangle quality; the first of equal trials.
/// Returns its index (0 for an empty list).
std::size_t best_corner_trial(const std::vector<CornerTrial>& trials);

/// Everything the front half produces, for writers and reports.
/// One stage of the front's nested optimization (FrontResult::stages): where
/// it started and how many cells were inverted at its start and end.
struct FrontStage {
  std::size_t cells = 0;
  /// The previous stage's positions carried over to this stage's finer mesh,
  /// or the Coons positions of this mesh: whichever has fewer inverted cells
  /// (the carried ones on a tie; the first stage starts from Coons).
  bool carried = false;
  std::size_t start_inverted = 0;  ///< inverted cells of the start taken
  /// Inverted cells of the start not taken, where both were counted (not
  /// where the previous stage ended with none: it is carried over then).
  std::optional<std::size_t> other_start_inverted;
  std::size_t end_inverted = 0;  ///< after the stage's optimization
  int sweeps = 0;
};

struct FrontResult {
  explicit FrontResult(BoundaryMap b) : boundary(std::move(b)) {}
  BoundaryMap boundary;
  TMesh mesh = TMesh(0);
  double tolerance_area = 0.0;
  bool tolerance_is_relative = true;
  BoundaryRefinementReport refinement;
  std::vector<Eigen::Vector2d> coons;      ///< positions after the Coons start (on the T-mesh before any repair)
  std::vector<Eigen::Vector2d> optimized;  ///< after untangling and smoothing
  MeshQualityStats quality_coons;  ///< of the Coons start, on the T-mesh before any repair
  MeshQualityStats quality_optimized;
  meshopt::SmoothingReport smoothing;  ///< of the last optimization run
  int total_sweeps = 0;                 ///< over all optimization runs
  std::size_t node_visits = 0;          ///< node optimizations over all runs
  /// Cells refined in each repair round (inverted cells after optimization).
  std::vector<std::size_t> repair_refined_cells;
  /// Why the repair stopped with inverted cells left ("" if none are left or
  /// the repair rounds ran out).
  std::string repair_stop_reason;
  std::vector<FrontStage> stages;  ///< the nested optimization's stages, coarse to fine (not the repairs)
  std::vector<CornerTrial> corner_trials;  ///< empty unless automatic corners were tried
  std::vector<StageTime> times;
  /// What clean_polygon removed from the input (file numbering), one note each.
  std::vector<std::size_t> removed_vertices;
  std::vector<std::string> cleaning_notes;
};

/// \throw InputError naming the first option out of range (options_validation.cpp).
void validate_options(const ParameterizationOptions& options);

/// Runs the front half on a polygon as read from a file (not yet validated).
/// \throw InputError for invalid polygons, corners or options.
FrontResult run_front(const Polygon& polygon, const ParameterizationOptions& options);

}  // namespace tspline
