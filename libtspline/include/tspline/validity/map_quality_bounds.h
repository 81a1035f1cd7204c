#pragma once
// Certified lower bounds of the mean ratio Jacobian J_r = 2 det J / |J|_F^2 and
// of the scaled Jacobian SJ = det J / (|S_xi| |S_eta|) of the T-spline map, per
// Bezier element and over the whole map (DESIGN.md §6, "Honest quality
// figures"). A sample can miss the minimum inside an element; these bounds
// cannot (up to floating-point round-off, see "Round-off" below).
//
// On a Bezier element e of size h_xi x h_eta with local coordinates (s, t) the
// map is S = X / w, X = sum_a P_a N_a (a vector) and w = sum_a N_a of bidegree
// (3,3) (map_certification.h). With subscripts for derivatives,
//
//   S_s = N_s / w^2,  N_s = X_s w - X w_s   (vector, bidegree (2+3, 3+3) = (5,6)),
//   S_t = N_t / w^2,  N_t = X_t w - X w_t   (vector, bidegree (6,5)),          (1)
//
// (the (6,6) terms X_s w and X w_s each have degree 5 in s since X_s and w_s
// have degree 2 in s), and det(N_s, N_t) = w D with D the (8,8) numerator of
// map_certification.h, det dS/d(s,t) = D / w^3. In parametric coordinates
// S_xi = S_s / h_xi, S_eta = S_t / h_eta, so with r = h_eta / h_xi
//
//   J_r = 2 D w / Q,   Q = r |N_s|^2 + |N_t|^2 / r,                           (2)
//   SJ  = D w / (|N_s| |N_t|).                                                 (3)
//
// Bounds on a patch of the element (the element or a de Casteljau sub-patch):
// the polynomials below are written in the tensor-product Bernstein basis of
// the patch. The basis functions are non-negative and sum to one, so a
// polynomial's values are convex combinations of its coefficients. Two lower
// bounds follow for each quantity; the patch's bound is the larger.
//  (a) The ratio bound. A = 2 D w (bidegree (11,11)), S2 = |N_s|^2 (10,12)
//      and T2 = |N_t|^2 (12,10) are formed by exact Bernstein products and
//      elevated to (12,12), so that J_r = A / (r S2 + T2 / r) by (2) is a
//      ratio of two polynomials in the same basis, sum_k b_k A_k / sum_k b_k Q_k.
//      If every Q_k > 0,
//        J_r >= min_k A_k / Q_k,   Q_k = r S2_k + T2_k / r                    (8)
//      (A - c Q = sum_k b_k (A_k - c Q_k) >= 0 for c the minimum, whatever the
//      signs of the A_k: (8) also bounds a folded patch). For SJ, by
//      AM-GM, rho |N_s|^2 + |N_t|^2 / rho >= 2 |N_s| |N_t| for any rho > 0, so
//      where A >= 0 (every A_k >= 0) SJ >= min_k A_k / (rho S2_k + T2_k / rho);
//      rho is the ratio of the mean coefficients of T2 and S2 to the power 1/2
//      (the best rho at a point is |N_t| / |N_s|, and the loss is second order
//      in its error). Exact where A and Q are constant (affine maps); the
//      coefficients converge to the values at rate O(h^2) on a sub-patch of size h.
//  (b) The cone bound. For the vector polynomial N_s with coefficients c_k,
//      N_s(p) = sum b_k(p) c_k, so
//        |N_s(p)| <= max_k |c_k|,   |N_s(p)| >= |c| - max_k |c_k - c|          (4), (5)
//      (c: the mean), and if the c_k lie in an open half-plane (all within 90
//      degrees of their mean direction m), N_s(p) lies in the cone they span,
//      angle(N_s) in [lo_s, hi_s], and |N_s| >= min_k c_k . m / |m|;          (6)
//      the same for N_t. With phi the angle from N_s to N_t and
//      tau = |N_t| / (r |N_s|),
//        SJ = sin phi,   J_r = g(tau) sin phi,   g(tau) = 2 tau / (1 + tau^2),  (7)
//      so SJ >= sigma = min of sin over [lo_t - hi_s, hi_t - lo_s], and, g
//      being unimodal (max 1 at tau = 1), J_r >= sigma min(g(tau_lo), g(tau_hi))
//      over tau in [b_lo / (r a_hi), b_hi / (r a_lo)] (a: bounds of |N_s|, b:
//      of |N_t|) if sigma >= 0 (J_r >= sigma otherwise). Sharp from the start
//      where the parameter lines are straight and only the speed varies (SJ = 1
//      of a graded map), where (a) converges only with subdivision.
// Both are clamped below at -1 (|J_r| <= |SJ| <= 1), which is also the bound
// where neither applies (a fold: A_k < 0 and the cones not separated). The
// bound of the element is the smallest over its final sub-patches.
//
// Subdivision (branch and bound): the corner coefficients of a patch are the
// values of the polynomials at its corners, so (2) and (3) at the corners are
// attained values, upper bounds U of the element's true minimum. The patch with
// the smallest lower bound L is split at s = t = 1/2 (de Casteljau on A, S2,
// T2 and the four components of N_s, N_t), until U - L <= relative_gap |U| +
// absolute_gap for both J_r and SJ, or the patch to split is at max_depth
// (each level halves both directions), or the element has max_patches patches.
// The ratio bound converges at rate O(h^2), so the gap falls by about 4 per
// level near a regular minimum: on the pipeline maps of the test polygons and
// coastlines at most 2-6 levels for 2 %, most elements none (the tests measure
// it). The (12,12) forms of (a) are made only for an element where (b) on the
// whole element does not already reach the gap (most elements of fine maps).
//
// Round-off: the arithmetic is ordinary floating point, not interval
// arithmetic (as in map_certification.h). The coefficients of A are lowered by
// round_off (1e-12) times 2 ElementJacobian::scale max|w| (scale: a bound of
// |D| from the magnitudes of its factors; the accumulated round-off of the
// extraction, the products, the elevation and the subdivisions is some 1e-15
// to 1e-14 of it) and the denominators raised (or lowered, for a negative
// numerator) by the factor 1 + round_off; the norm bounds (4), (5) are
// widened by the same factor; the cones (6) are used only if no coefficient is
// below 1e-6 of the largest, and widened by the angle error of a coefficient
// off by 1e3 eps of the largest (1e3 eps max|c| / |c_k| rad). So the bounds
// are rigorous unless the round-off exceeds ~100 times its usual size. For an affine map A, S2, T2 are
// constant: the bounds equal the exact J_r and SJ up to ~1e-12.
//
// Over a map (without per_element), an element's bound is carried to the gap
// only where it can hold the map's minimum: first every element gets the cone
// bound (b) on the whole element and the values at its corners; then the
// elements whose two cone bounds are not both above the least J_r and the
// least SJ at those corners (values of the map) are bounded as above. The
// others' cone bounds exceed a value the map attains, so they cannot be its
// minimum bound: the map's figures are those of every element carried to the
// gap wherever subdivision does not lower an element's bound below its cone
// bound (bit for bit on the maps of the tests and of the bundled domains), and
// certified in any case. On Newfoundland's 5,151-patch map (158,547 elements,
// bench_quality_bounds on one thread) 1.66 -> 1.37 s, the same figures.
//
// The dense sample (samples_per_edge = k > 0): J_r and SJ at (k + 1)^2 points
// of a uniform grid including the element's corners and edges, evaluated from
// the same Bernstein forms of X and w (not from the bounds). It is reported
// next to the bound as a check: bound <= true minimum <= sampled minimum.
// Over a map (without per_element) the sample is taken only where it can hold
// the map's sampled minimum: an element's sampled values are at least its
// bounds, so the elements are sampled in ascending order of their bounds until
// the next bound exceeds the least value sampled. The map's sampled minimum,
// its element and its point are those of a sample of every element (every
// element that could equal the minimum is sampled); the other elements keep
// `sampled` = 1. On a coastline's 8,776-patch map 7 % of the elements
// (bench_quality_bounds: 4.4 -> 2.6 s on one thread).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

struct QualityBoundOptions {
  /// Stop splitting an element once (attained minimum - bound) <= relative_gap
  /// |attained minimum| + absolute_gap, for J_r and for SJ.
  double relative_gap = 0.02;
  double absolute_gap = 1e-4;
  int max_depth = 10;             ///< subdivision levels at most
  std::size_t max_patches = 1024; ///< sub-patches examined per element at most
  /// Dense sample: (k + 1)^2 points per element (k = 25: 26 x 26); 0 = none.
  int samples_per_edge = 25;
  /// Threads over elements (0: std::thread::hardware_concurrency()).
  int threads = 0;
  /// Keep the per-element results (MapQualityBounds::per_element); every
  /// element then has its own dense sample.
  bool per_element = false;
};

/// The bound of one quantity (J_r or SJ) on one element or over a map.
struct QualityBound {
  /// Certified: the quantity is >= this everywhere on the element (map).
  double lower_bound = 1.0;
  /// The smallest value attained at the sub-patch corners looked at (a true
  /// value of the map: the minimum lies in [lower_bound, attained]).
  double attained = 1.0;
  Eigen::Vector2d attained_at = Eigen::Vector2d::Zero();  ///< parametric point of `attained`
  /// Dense sample (if samples_per_edge > 0; 1 otherwise): the smallest sampled value and where.
  double sampled = 1.0;
  Eigen::Vector2d sampled_at = Eigen::Vector2d::Zero();
  /// Over a map: the elements (extraction order; over several maps counted
  /// through the maps in order) of lower_bound, attained and sampled.
  std::size_t lower_bound_element = 0, attained_element = 0, sampled_element = 0;
};

struct ElementQualityBound {
  QualityBound mean_ratio, scaled;
  int depth = 0;              ///< deepest subdivision level used
  std::size_t patches = 0;    ///< sub-patches examined (1 = none split)
  bool converged = true;      ///< both gaps reached (not stopped by max_depth or max_patches)
};

struct MapQualityBounds {
  std::size_t elements = 0;
  /// Elements whose bounds were carried to the gap: all with per_element, else
  /// those that could hold the map's minimum (header, "Over a map"); the
  /// others have the cone bound on the whole element. depth, patches and
  /// elements_not_converged count these.
  std::size_t bounded_elements = 0;
  /// Elements whose dense sample was taken: all with per_element, else those
  /// that could hold the sampled minimum (header, "The dense sample").
  std::size_t sampled_elements = 0;
  /// Whole map: the minimum over the elements of each field (lower_bound,
  /// attained, sampled, each with its own element and location).
  QualityBound mean_ratio, scaled;
  int samples_per_edge = 0;              ///< k of the dense sample (0: none)
  std::size_t samples_per_element = 0;   ///< (k + 1)^2
  int max_depth_used = 0;
  std::size_t patches = 0;                ///< over all elements
  std::size_t elements_not_converged = 0; ///< stopped by max_depth or max_patches (bound still valid)
  double seconds = 0.0;
  std::vector<ElementQualityBound> per_element;  ///< if options.per_element, in extraction order
};

/// Bounds of J_r and SJ on one Bezier element of a map with control points P.
ElementQualityBound element_quality_bound(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                          const QualityBoundOptions& options = {});

/// Every element of the map, in parallel over elements.
MapQualityBounds certified_map_quality(const TSplineMap& map, const QualityBoundOptions& options = {});
MapQualityBounds certified_map_quality(const BezierExtraction& extraction, const std::vector<Eigen::Vector2d>& P,
                                       const QualityBoundOptions& options = {});
/// Several maps (the patches of a multi-patch map): the whole-map figures are
/// the minima over all patches; elements, patches, counts and seconds add up;
/// per_element concatenates the patches' elements in order; element indices
/// count through the patches in order, locations are in the parameter space of
/// the patch holding the element.
MapQualityBounds certified_map_quality(const std::vector<const TSplineMap*>& maps,
                                       const QualityBoundOptions& options = {});
/// The figures of several maps' bounds (parts, in patch order) as
/// certified_map_quality of the maps gives them (moves the per_element lists).
MapQualityBounds merge_map_quality(std::vector<MapQualityBounds>&& parts);

}  // namespace tspline
