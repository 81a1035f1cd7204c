#pragma once
// Quality of the T-spline map at Gauss points (Brovka 2013 Sect. 6.1):
//   mean ratio Jacobian J_r = 2 det J / |J|_F^2 (Eq. 9; 1 where S is conformal),
//   det J, and the scaled Jacobian J_s = det J / (|S_xi| |S_eta|).
// 0 <= |J_r| <= |J_s| <= 1.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "tspline/spline/tspline_map.h"

namespace tspline {

class BezierExtraction;

double mean_ratio_jacobian(const Eigen::Matrix2d& J);
double scaled_jacobian(const Eigen::Matrix2d& J);

struct CellMapQuality {
  double min_mean_ratio = 1.0;
  double min_det = 0.0;
  double min_scaled = 1.0;
};

struct MapQualityStats {
  std::size_t points = 0;
  std::size_t nonpositive_det = 0;  ///< quadrature points with det J <= 0
  double min_mean_ratio = 1.0;
  double mean_mean_ratio = 0.0;
  double min_det = 0.0;
  double max_det = 0.0;
  double min_scaled = 1.0;
};

/// Over all cells' gauss x gauss points; per cell too if `per_cell` is given.
MapQualityStats map_quality(const TSplineMap& map, int gauss = 4, std::vector<CellMapQuality>* per_cell = nullptr);
/// The same with the Bezier extraction of map.basis() given (built once for
/// several checks of maps on one T-mesh).
MapQualityStats map_quality(const TSplineMap& map, const BezierExtraction& extraction, int gauss,
                            std::vector<CellMapQuality>* per_cell = nullptr);

/// Quality over the whole map, not only at quadrature points: a dense sample
/// of every Bezier element (bezier_extraction.h), (k + 1) x (k + 1) points on a
/// uniform grid that includes the element's corners and edges (where the
/// Gauss points miss the worst values, e.g. at a corner of the square placed
/// on a nearly straight polygon vertex). A sample, not a bound: the certified
/// bound of det J is map_certification.h's.
struct DenseMapQuality {
  std::size_t elements = 0;
  std::size_t points = 0;
  std::size_t nonpositive_det = 0;
  double min_mean_ratio = 1.0;
  double min_scaled = 1.0;
  Eigen::Vector2d worst_at = Eigen::Vector2d::Zero();  ///< parametric point of min J_r
  int samples_per_edge = 0;                            ///< k
};

/// A pair of whole-map thresholds: the scaled Jacobian and J_r that a map's
/// dense-sample minima must reach (0 and 0: every valid map does).
struct QualityFloor {
  double scaled_jacobian = 0.0;
  double mean_ratio = 0.0;
  bool met_by(const DenseMapQuality& q) const {
    return q.min_scaled >= scaled_jacobian && q.min_mean_ratio >= mean_ratio;
  }
};

/// \pre k >= 1.
DenseMapQuality dense_map_quality(const TSplineMap& map, int k = 8);
/// The same from a Bezier extraction and control points (one per blending function).
DenseMapQuality dense_map_quality(const BezierExtraction& extraction, const std::vector<Eigen::Vector2d>& P, int k = 8);

}  // namespace tspline
