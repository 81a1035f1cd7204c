#pragma once
// The remesher's state and local operations (Dassi et al. 2014, Sect. 3.1):
// internal to libmeshopt; remesh() in remesh.cpp runs Algorithms 1-3 with it.
#include <array>
#include <vector>

#include "meshopt/metric6d.h"
#include "meshopt/remesh.h"

namespace meshopt::detail {

using Edge = std::array<int, 2>;

class Remesher {
 public:
  Remesher(RemeshMesh& mesh, const RemeshGeometry& geometry, const RemeshOptions& options, RemeshReport& report)
      : m_(mesh), g_(geometry), o_(options), r_(report) {}

  RemeshMesh& mesh() { return m_; }
  double length(int a, int b) const { return edge_length6d(m_, a, b, o_.anisotropy); }
  double min_angle(int t) const { return triangle_min_angle6d(m_, t, o_.anisotropy); }
  /// Longest (or shortest) 6D edge of live triangle t.
  Edge extreme_edge(int t, bool longest) const;
  /// Estimated chordal deviation of live triangle t (chordal_estimate.h).
  double deviation(int t) const { return deviation(m_.triangles[t].v, m_.triangles[t].patch); }
  /// True if options.max_deviation is set and live triangle t exceeds it.
  bool too_deviant(int t) const { return o_.max_deviation > 0.0 && deviation(t) > o_.max_deviation; }
  /// The edge of live triangle t with the largest |II(e, e)| (the most curved chord).
  Edge most_curved_edge(int t) const;

  /// Splits edge (a, b) at its midpoint projected onto the model (onto the
  /// feature curve for a feature edge). Returns the new vertex or -1.
  int split(int a, int b);
  /// Collapses edge (a, b) onto one of its end points if the link condition,
  /// the features and the inversion test allow it, and no new edge is longer
  /// than `max_length` (6D). Returns the kept vertex or -1.
  int collapse(int a, int b, double max_length);
  /// Flips edge (a, b) if criterion (a) or (b) of Sect. 3.1 says so.
  bool flip(int a, int b);
  /// Edge flips from the stack S until none applies (Sect. 3.1, with the
  /// paper's second stack S1; at most options.max_flip_passes passes).
  void improve_by_flips(std::vector<Edge> stack);
  /// improve_by_flips on every edge that may decide differently since the last
  /// call: the edges of the triangles around vertices that a split, collapse,
  /// flip or smoothing move touched (all edges the first time). An edge's flip
  /// depends only on its two triangles' corners (positions, normals) and on
  /// whether the other diagonal is an edge, which only a change at one of
  /// those corners alters.
  void improve_all_by_flips();
  /// Vertex smoothing (Eq. 6 with 6D distances, f(d) = -d, alpha = 1/#omega),
  /// then projection; `fraction` of the movable vertices that would move most.
  void smooth(double fraction);

 private:
  bool can_remove(int a, int b) const;
  bool collapse_onto(int a, int b, double max_length);
  /// Eq. 6 step of vertex v in R^3 (tangential for surface vertices), zero if fixed.
  /// `mean_length`, if given, receives the mean 3D length of v's edges.
  Eigen::Vector3d smoothing_step(int v, double* mean_length = nullptr) const;
  bool move_vertex(int v, const Eigen::Vector3d& target);
  std::array<Eigen::Vector3d, 3> positions(const std::array<int, 3>& t) const;
  std::array<Eigen::Vector3d, 3> normals(const std::array<int, 3>& t, int patch) const;
  bool inverted(const std::array<int, 3>& t, int patch) const;
  double min_angle(const std::array<int, 3>& t, int patch) const;
  double deviation(const std::array<int, 3>& t, int patch) const;
  /// True if a triangle `t` that replaces one of estimated deviation `before`
  /// breaks the cap: above options.max_deviation (when set) and above `before`.
  bool breaks_cap(const std::array<int, 3>& t, int patch, double before) const;
  /// Eq. 5 for the two triangles t1, t2 (given as corner triples in one patch).
  double pair_energy(const std::array<int, 3>& t1, const std::array<int, 3>& t2, int patch) const;
  /// The projection hint of triangles `tris`, with the faces of `first` first.
  ProjectionHint hint(const std::vector<int>& tris, std::initializer_list<int> first) const;

  RemeshMesh& m_;
  const RemeshGeometry& g_;
  const RemeshOptions& o_;
  RemeshReport& r_;
  void touch(int v);
  std::vector<int> touched_;      ///< vertices touched since the last improve_all_by_flips
  std::vector<char> is_touched_;  ///< per vertex
  bool all_touched_ = true;
  mutable std::vector<int> neighbour_scratch_;  ///< smoothing_step's, reused (no allocation per call)
};

}  // namespace meshopt::detail
