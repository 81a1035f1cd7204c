#pragma once
// The whole parameterization (Brovka 2013 Sects. 3-6): the front half (T-mesh,
// Coons, untangling and smoothing), the cubic T-spline fit, the mean ratio
// Jacobian check, and adaptive refinement of the cells where it is poor
// (Sect. 6.2) until the map is valid and good or the round limit is reached.
// Validity is also certified on every Bezier element (map_certification.h): a
// cell with an element that is not certified is refined like one with J_r < delta.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tspline/control_point_optimization.h"
#include "tspline/map_certification.h"
#include "tspline/map_quality.h"
#include "tspline/parameterization.h"
#include "tspline/tspline_fit.h"
#include "tspline/tspline_map.h"

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
  /// Never refine beyond this many cells.
  std::size_t max_cells = 200000;
  /// After each fit that is not valid and good, optimize the interior control
  /// points acting on cells with J_r < 2 min_jacobian for the Jacobian
  /// (control_point_optimization.h) and keep the result if it is better.
  bool optimize_control_points = true;
  /// Exponent p of that optimization's objective sum_g (1/J_r)^p (regularized).
  /// p = 1 is the paper's K* and favours the mean; larger p pushes up the
  /// minimum J_r, which is what the threshold asks for. On the bundled domains
  /// p = 4 raised the minimum from 0.12-0.25 to 0.21-0.45 at a few % of mean.
  double control_point_power = 4.0;
  /// Certify det J > 0 on every Bezier element after each fit; refine the cells
  /// that are not certified, and stop only once the map is certified.
  bool certify = true;
  CertificationOptions certification;
};

struct AdaptIteration {
  std::size_t cells = 0;
  std::size_t vertices = 0;
  std::size_t functions = 0;
  std::size_t inverted_cells = 0;  ///< of the optimized T-mesh
  std::size_t refined_cells = 0;   ///< cells marked after this iteration (0 for the last)
  FitReport fit;
  bool control_points_optimized = false;
  MapQualityStats quality;         ///< of the map kept in this iteration
  /// Certification of that map (counts and bounds; no per-cell data).
  MapCertification certification;
  std::size_t certification_marked_cells = 0;  ///< cells marked only because they are not certified
  double seconds = 0.0;            ///< optimization (after refinement) + fit + check
};

struct ParameterizationResult {
  FrontResult front;  ///< mesh/optimized/quality_optimized are those of the kept T-mesh
  std::optional<TSplineMap> map;
  FitReport fit;
  MapQualityStats quality;
  std::vector<CellMapQuality> cell_quality;
  std::vector<AdaptIteration> iterations;
  int kept_iteration = 0;       ///< the best iteration, whose mesh and map these are
  /// Whether the kept map's interior control points were optimized (so it does
  /// not interpolate the interior T-mesh vertices).
  bool control_points_optimized = false;
  std::string stop_reason;      ///< why the adaptive loop stopped
  MapCertification certification;  ///< of the kept map (empty if AdaptiveOptions::certify is off)
  /// Refinement rounds made only because of the certification: the map was
  /// valid and good at every Gauss point but not certified on every element.
  int certification_rounds = 0;
  bool valid() const { return quality.nonpositive_det == 0; }
  bool certified_valid() const { return certification.certified_valid(); }
  bool good(double min_jacobian) const { return valid() && quality.min_mean_ratio >= min_jacobian; }
};

/// Called after each fit with the iteration number (0 = first fit), the T-mesh,
/// its physical vertex positions, the map and its per-cell quality.
using IterationCallback = std::function<void(int, const TMesh&, const std::vector<Eigen::Vector2d>&,
                                             const TSplineMap&, const std::vector<CellMapQuality>&)>;

/// \throw InputError for invalid input or options; NumericalError if a fit fails.
ParameterizationResult run_parameterization(const Polygon& polygon, const ParameterizationOptions& options,
                                            const AdaptiveOptions& adaptive, const IterationCallback& on_iteration = {});

}  // namespace tspline
