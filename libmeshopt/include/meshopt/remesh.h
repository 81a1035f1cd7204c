#pragma once
// Curvature-adapted anisotropic remeshing of CAD surfaces (Dassi, Mola & Si
// 2014, Sect. 3): local operations (edge split, collapse, flip, vertex
// smoothing) driven by edge lengths and angles in the R^6 embedding
// Phi(x) = (x, s n(x)), until every edge has 6D length about L. The result is
// stretched along directions of low curvature (Sect. 2.1).
//
// RE-MESHING (Algorithm 3) = K times { SAMPLING (Algorithm 1: split > 1.5 L,
// flips, collapse < 0.5 L, flips); OPTIMIZING (Algorithm 2: I times { J times
// { smooth 30% of the vertices, flips }, collapse at angles < theta_min, flips }) }.
//
// Beyond the paper: collapses keep the link condition (no change of topology)
// and the features (a vertex leaves a feature curve never; a corner never
// moves); no operation leaves a triangle inverted against the CAD normal
// (Definition 3.4) that was not; every flip loop is capped; an optional cap on
// the chordal deviation (max_deviation).
#include <cstddef>
#include <functional>
#include <numbers>
#include <string>

#include "meshopt/remesh_mesh.h"

namespace meshopt {

struct RemeshOptions {
  double length = 1.0;      ///< L: target 6D edge length (> 0)
  double anisotropy = 0.0;  ///< s in Phi (>= 0; 0: isotropic remeshing in R^3)
  double min_angle = 20.0 * std::numbers::pi / 180.0;  ///< theta_min (radians)
  int rounds = 3;           ///< K (Algorithm 3)
  int outer = 4;            ///< I (Algorithm 2)
  int inner = 4;            ///< J (Algorithm 2)
  double smooth_fraction = 0.3;  ///< vertices smoothed per pass (Algorithm 2, line 3)
  double inversion_angle = std::numbers::pi / 2.0;  ///< alpha (Definition 3.4)
  /// D: cap on the chordal deviation of every triangle's centroid, estimated
  /// from its corner normals (chordal_estimate.h); 0: no cap (the paper).
  /// Triangles above it are split (their most curved edge) in SAMPLING, and no
  /// collapse, flip or smoothing move may push a triangle above it.
  double max_deviation = 0.0;
  int max_flip_passes = 50;  ///< cap of each edge-flip loop (waves of link edges after the first pass)
  /// Called at each phase with (round, phase name); may be empty.
  std::function<void(int, const std::string&)> progress;
};

struct RemeshReport {
  std::size_t splits = 0, collapses = 0, flips = 0, smoothing_moves = 0;
  std::size_t rejected_collapses = 0;  ///< refused by the link/feature/inversion checks
  double seconds_sampling = 0.0, seconds_optimizing = 0.0;
};

/// Remeshes `mesh` in place (compacted at the end).
/// \throw toolkit::InputError (a std::invalid_argument) for invalid options.
RemeshReport remesh(RemeshMesh& mesh, const RemeshGeometry& geometry, const RemeshOptions& options);

/// 6D length of edge (a, b) of `mesh`: the largest over the patches of its
/// triangles (normals differ across a feature curve).
double edge_length6d(const RemeshMesh& mesh, int a, int b, double s);

/// The chordal deviation of live triangle t's centroid estimated from its corner
/// normals (triangle_deviation_estimate).
double triangle_deviation(const RemeshMesh& mesh, int t);

/// Smallest 6D angle of live triangle t.
double triangle_min_angle6d(const RemeshMesh& mesh, int t, double s);

}  // namespace meshopt
