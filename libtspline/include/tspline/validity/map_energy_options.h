#pragma once
// The options of the map's distortion energy (the energy itself is internal:
// libtspline/internal/tspline/validity/map_energy.h) and the statistics of its
// sample points, as the untangling reports them (map_untangling.h).
#include <cstddef>
#include <vector>

namespace tspline {

enum class ElementWeighting {
  Uniform,  ///< every Bezier element has weight 1
  Area      ///< weight = parametric area (an integral over the square)
};

struct MapEnergyOptions {
  /// Points per direction per sub-square: Gauss-Lobatto (end points
  /// included, n in [3, 5]) or Gauss-Legendre (n in [1, 6]).
  int gauss = 5;
  /// Gauss-Lobatto: samples on every element's corners and edges too. Measured
  /// on Newfoundland: with 4 x 4 Gauss-Legendre points the optimizer folded the
  /// map between samples along element edges (1,317 folded samples after the
  /// first sample refinement, then a long second continuation).
  bool lobatto = true;
  double theta = 1.0 / 128;  ///< weight of the area term, in [0, 1)
  int max_sample_level = 3;  ///< sample levels 0..this (2^l x 2^l sub-squares per element)
  /// Uniform: small elements along a detailed coastline count as much as large
  /// interior ones, which is where maps fold (measured on the bundled
  /// coastlines: fewer continuation stages than Area).
  ElementWeighting weighting = ElementWeighting::Uniform;
  /// Threads for the energy and gradient (0: std::thread::hardware_concurrency).
  int threads = 0;
  /// Per basis function: may it move? Empty: every function not touching the
  /// border. Otherwise only those marked (and not touching the border) are
  /// variables, and only the elements they touch enter the energy (a local
  /// problem: the rest of the map is fixed and adds a constant).
  std::vector<char> movable;
};

/// Statistics over the current sample points (not a certificate).
struct SampleStats {
  std::size_t points = 0;
  std::size_t nonpositive = 0;  ///< samples with det J <= 0
  double min_det = 0.0;         ///< min det J / L^2 (normalized: 1 on average)
  double min_mean_ratio = 0.0;  ///< min J_r
  double mean_mean_ratio = 0.0; ///< weighted mean J_r
};

}  // namespace tspline
