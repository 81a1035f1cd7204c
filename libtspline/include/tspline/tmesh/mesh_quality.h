#pragma once
// Validity and shape quality of the physical T-mesh cells.
//
// A cell is judged by the triangles the optimization sees in it: the four corner
// triangles of its quadrilateral and, for each hanging vertex h on its edges, the
// five triangles (h, p, q) of Sect. 4.2 (pairs of corners not collinear with h).
// Each triangle's quality is the mean ratio q = 2 sigma / |S|^2 against its
// parametric counterpart (q = 1: similar, q <= 0: flat or inverted). A cell is
// valid iff all its triangles have sigma > 0.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// The triangles of cell c as vertex triples, counter-clockwise in [0,1]^2.
std::vector<std::array<int, 3>> cell_triangles(const TMesh& mesh, int c);

struct CellQuality {
  bool valid = true;
  double min_mean_ratio = 1.0;  ///< smallest triangle mean ratio (negative if inverted)
};

struct MeshQualityStats {
  std::size_t cells = 0;
  std::size_t inverted_cells = 0;
  std::size_t triangles = 0;
  std::size_t inverted_triangles = 0;
  double min_mean_ratio = 1.0;   ///< over all triangles
  double mean_mean_ratio = 0.0;  ///< over all triangles
};

/// Quality of every cell for physical vertex positions x (indexed by vertex id).
std::vector<CellQuality> cell_qualities(const TMesh& mesh, const std::vector<Eigen::Vector2d>& x);

MeshQualityStats mesh_quality(const TMesh& mesh, const std::vector<Eigen::Vector2d>& x);

}  // namespace tspline
