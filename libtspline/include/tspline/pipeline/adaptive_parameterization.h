#pragma once
// The whole parameterization, in named steps:
//  1. front half (Brovka 2013 Sects. 3-4): T-mesh adapted to the boundary,
//     Coons start, weighted K* untangling and smoothing of the T-mesh;
//  2. first map: the cubic T-spline interpolating the T-mesh (Sect. 5). Its
//     border control points define the boundary curve, frozen from here on;
//     det J at the four corners of the square (the cross product of the two
//     boundary tangents there, which no interior move changes) is checked;
//  3. global untangling and smoothing of the map's own interior control points
//     until det J > 0 is certified on every Bezier element (map_untangling.h);
//  4. quality: mean ratio J_r at Gauss points (the paper's check, Sect. 6.1),
//     over a dense sample of every element, and the certificate;
//  5. if not certified or J_r < delta somewhere: refine those cells (the
//     uncertified ones with a ring of neighbours), re-balance, carry the
//     current map onto the finer T-mesh (transfer_map: the boundary curve is
//     reproduced exactly) and go on from it at step 3 (Sect. 6.2, without
//     re-interpolating from scratch).
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"
#include "tspline/validity/map_untangling.h"
#include "tspline/pipeline/parameterization.h"
#include "tspline/spline/tspline_fit.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

struct AdaptiveOptions {
  double min_jacobian = 0.2;  ///< delta: refine cells where J_r < delta at some Gauss point
  int max_adapt = 10;         ///< adaptive rounds at most
  int gauss = 4;              ///< Gauss points per direction and cell for the check
  /// Stop when the best iteration (fewest det J <= 0 points, then certified
  /// valid before not, then highest min J_r) has not improved for this many rounds: refinement cannot fix
  /// distortion that the corner choice imposes (a long strip mapped onto the
  /// square keeps its aspect ratio however fine the mesh).
  int stall_rounds = 2;
  /// Once the map is certified, refine for J_r < delta only while each round
  /// raises the whole-map min J_r by at least this fraction (where the minimum
  /// is set by the boundary and the corners, refinement only adds cells:
  /// Hispaniola went from 0.077 to 0.096 over 5 rounds and 1,057 to 55,774 cells).
  /// 0 disables this stop.
  double min_quality_gain = 0.1;
  /// Once certified, no round refines more than this fraction of the cells for
  /// J_r < delta alone (measured on Newfoundland: 3,647 of 6,964 cells below
  /// 0.2 after certification; three more rounds reached 59,506 cells for a
  /// minimum of 0.024 -> 0.032).
  double max_quality_fraction = 0.25;
  // The cell budget is ParameterizationOptions::max_cells (one for the front half and this loop).
  /// Untangle and smooth the interior control points of every map globally
  /// (map_untangling.h). false: keep the interpolating map of the T-mesh.
  bool optimize_control_points = true;
  /// Where the interpolating map is certified and its whole map (dense sample
  /// and Gauss points) already meets this floor, it is kept as it is, without
  /// the optimization (unset: always optimized). Such a map is rarely the one
  /// that sets a layout's minimum, and on a quad layout most patches are such.
  /// Measured on the 30 shared domains (default options): 160.6 -> 142.5 s in
  /// all (Newfoundland 53.7 -> 48.9 s, the Maldives 27.5 -> 21.9 s), the
  /// certified whole-map figures the same on 26; of the other four, where the
  /// map's minimum is near or above the floor, the Aeolian sea's scaled
  /// Jacobian fell 0.628 -> 0.617 and three rose or moved by 0.001. With a
  /// floor of 0.5, four maps lost up to 0.036 of their scaled Jacobian.
  std::optional<QualityFloor> keep_interpolant = QualityFloor{0.6, 0.6};
  MapUntanglingOptions untangling;
  /// The map kept, where certified but its whole-map J_r (dense sample) is
  /// below polish_below, gets more quality stages of the untangling
  /// (map_untangling.h: at most polish_stages, each sample's term to the power
  /// polish_power, closer to the minimum), kept where the whole-map J_r rises
  /// and the map stays certified. Measured on a patch of a coastline's quad
  /// layout: 3 quality stages J_r 0.25, 30 stages 0.33, and power 8 0.38.
  /// polish_stages = 0: no polish.
  double polish_below = 0.3;
  int polish_stages = 12;
  double polish_power = 8.0;
  /// No polish where the whole map misses polish_skip (dense sample; the
  /// default 0 and 0: never skipped).
  /// Auto's first try of one patch sets them to a half (scaled Jacobian) and
  /// a quarter (J_r) of what it calls good: there a polish cannot make the map
  /// good (it raised the scaled Jacobian by 1.6x at most, J_r by 1.9x, on the
  /// bundled coastlines' single patches) and would only delay the layout
  /// (1-2 s of a coastline's try).
  QualityFloor polish_skip;
  /// dense_map_quality: (k + 1)^2 samples per Bezier element.
  int dense_samples = 8;
  /// Certify det J > 0 on every Bezier element after each fit; refine the cells
  /// that are not certified, and stop only once the map is certified.
  bool certify = true;
  /// How det J > 0 is certified, by this loop and by the untangling it runs (one owner).
  CertificationOptions certification;
  /// Called once the first round's boundary curve is frozen (after its checks
  /// and refits, before any untangling): a non-empty text stops the run, which
  /// throws ParameterizationStopped(text). From there on the boundary, and with
  /// it J at the corners of the square (corner_quality.h), stay as in the map
  /// passed. Lets a caller that needs a given quality give up on a map whose
  /// corners already rule it out.
  std::function<std::string(const TSplineMap&)> stop_when_boundary_frozen;
};

struct AdaptIteration {
  std::size_t cells = 0;
  std::size_t vertices = 0;
  std::size_t functions = 0;
  std::size_t inverted_cells = 0;  ///< of the optimized T-mesh
  std::size_t refined_cells = 0;   ///< cells marked after this iteration (0 for the last)
  FitReport fit;                   ///< interpolation (iteration 0) or transfer of the previous map
  bool control_points_optimized = false;
  /// The global untangling of this iteration (no per-element data).
  MapUntanglingReport untangling;
  MapQualityStats quality;         ///< of the map kept in this iteration, at Gauss points
  DenseMapQuality dense_quality;   ///< of that map, over a dense sample of every element
  /// Certification of that map (counts and bounds; no per-cell data).
  MapCertification certification;
  std::size_t certification_marked_cells = 0;  ///< cells marked only because they are not certified
  double seconds = 0.0;            ///< fit or transfer + untangling + checks
};

struct ParameterizationResult {
  explicit ParameterizationResult(FrontResult f) : front(std::move(f)) {}
  FrontResult front;  ///< mesh/optimized/quality_optimized are those of the kept T-mesh
  std::optional<TSplineMap> map;
  FitReport fit;
  MapQualityStats quality;          ///< at Gauss points
  /// Over a dense sample of every Bezier element and the Gauss points (the
  /// smaller of the two minima; worst_at is a cell centre if a Gauss point is worse).
  DenseMapQuality dense_quality;
  std::vector<CellMapQuality> cell_quality;
  std::vector<AdaptIteration> iterations;
  int kept_iteration = 0;       ///< the best iteration, whose mesh and map these are
  /// Whether the kept map's interior control points were optimized (so it does
  /// not interpolate the interior T-mesh vertices).
  bool control_points_optimized = false;
  std::string stop_reason;      ///< why the adaptive loop stopped
  /// Empty, or why no interior move can make the map valid (det J <= 0 at a
  /// corner of the square, decided by the frozen boundary curve alone).
  std::string boundary_problem;
  bool boundary_simple = false;  ///< the frozen boundary curve is proven simple (boundary_curve.h)
  MapCertification certification;  ///< of the kept map (empty if AdaptiveOptions::certify is off)
  /// Refinement rounds made only because of the certification: the map was
  /// valid and good at every Gauss point but not certified on every element.
  int certification_rounds = 0;
  /// The options this result was computed with (without the progress
  /// callback), so that reports and writers need nothing else.
  ParameterizationOptions options;
  AdaptiveOptions adaptive;
  bool valid() const { return quality.nonpositive_det == 0; }
  bool certified_valid() const { return certification.certified_valid(); }
  /// Valid and J_r >= adaptive.min_jacobian at every Gauss point (the paper's criterion).
  bool good() const { return valid() && quality.min_mean_ratio >= adaptive.min_jacobian; }
};

/// Called after each fit with the iteration number (0 = first fit), the T-mesh,
/// its physical vertex positions, the map and its per-cell quality.
using IterationCallback = std::function<void(int, const TMesh&, const std::vector<Eigen::Vector2d>&,
                                             const TSplineMap&, const std::vector<CellMapQuality>&)>;

/// \throw InputError naming the first option out of range (options_validation.cpp).
void validate_options(const AdaptiveOptions& options);

/// A map to start the adaptive loop from instead of the interpolant of the
/// front half's T-mesh (a moved boundary: deform/reparameterization.h).
struct WarmStart {
  TSplineMap map;  ///< on front.mesh, its boundary curve on front.boundary's polygon
  /// Whole-map J_r (dense sample) of the map it was moved from. Round 0 keeps
  /// the warm map as it is if it is certified and its whole-map J_r is at
  /// least (1 - keep_loss) times this; else it is untangled and improved like
  /// a fitted map.
  double reference_mean_ratio = 0.0;
  /// The relative loss of whole-map J_r a warm map may have and still be kept
  /// without optimization (over 20 such steps at most 1 - 0.98^20 = 33 %; an
  /// optimized step restores the quality). 0: only maps as good as before.
  double keep_loss = 0.02;
  /// Round 0 stops (no refinement) once certified with at least this fraction
  /// of reference_mean_ratio; below it the usual refinement rules apply.
  double keep_fraction = 0.9;
  /// Quality stages of the untangling at most (MapUntanglingOptions::
  /// max_quality_stages): the warm map starts near the previous optimum.
  int quality_stages = 2;
};

/// \throw InputError for invalid input or options; NumericalError if a fit fails.
ParameterizationResult run_parameterization(const Polygon& polygon, const ParameterizationOptions& options,
                                            const AdaptiveOptions& adaptive, const IterationCallback& on_iteration = {});

/// Steps 2-5 from a warm start on `front` (its mesh, vertex positions and
/// boundary map: the front half is not run). \throw as run_parameterization.
ParameterizationResult run_parameterization_from(FrontResult front, WarmStart warm,
                                                 const ParameterizationOptions& options,
                                                 const AdaptiveOptions& adaptive,
                                                 const IterationCallback& on_iteration = {});

}  // namespace tspline
