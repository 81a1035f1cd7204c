#pragma once
// What a remeshed surface looks like (Dassi et al. 2014, Sect. 5): 6D edge
// lengths relative to L, smallest 6D angles, and the 3D aspect ratio
// q(T) = 2 r_T / R_T (1 for an equilateral triangle, 0 for a degenerate one).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "meshopt/remesh_mesh.h"

namespace meshopt {

/// Counts of values in [lo + k width, lo + (k + 1) width); the last bin also
/// takes everything above, the first everything below.
struct Histogram {
  double lo = 0.0, width = 1.0;
  std::vector<std::size_t> counts;
  void add(double value);
};

/// q(T) = 2 r / R (inscribed over circumscribed radius); 0 if degenerate.
double aspect_ratio(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2);

/// Unit direction of the triangle's largest extent: the principal axis of the
/// second moment of its vertices.
Eigen::Vector3d long_axis(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2);

struct RemeshStatistics {
  std::size_t vertices = 0, triangles = 0, edges = 0;
  Histogram length_ratio{0.0, 0.1, std::vector<std::size_t>(20)};     ///< 6D edge length / L
  Histogram min_angle_degrees{0.0, 5.0, std::vector<std::size_t>(12)};  ///< smallest 6D angle per triangle
  double length_ratio_min = 0.0, length_ratio_mean = 0.0, length_ratio_max = 0.0;
  double min_angle_min = 0.0, min_angle_mean = 0.0;  ///< degrees
  double quality_min = 0.0, quality_mean = 0.0;      ///< 3D aspect ratio
};

/// Statistics of the live triangles of `mesh` for target length L and anisotropy s.
RemeshStatistics remesh_statistics(const RemeshMesh& mesh, double length, double s);

/// Per live triangle (in order): q(T), and the mean 6D length / L of its edges.
std::vector<double> triangle_aspect_ratios(const RemeshMesh& mesh);
std::vector<double> triangle_length_ratios(const RemeshMesh& mesh, double length, double s);

}  // namespace meshopt
