#pragma once
// The triangle mesh the remesher edits (Dassi et al. 2014, Sect. 3): vertices
// classified on the CAD model, triangles each in one patch, the feature edges
// (mesh edges on feature curves) and the vertex-triangle incidence that the
// local operations keep up to date.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <compare>
#include <functional>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <utility>
#include <vector>

#include "meshopt/remesh_geometry.h"

namespace meshopt {

/// An undirected mesh edge, its ends in increasing order: the key of per-edge data.
struct EdgeKey {
  int a = 0, b = 0;  ///< a <= b
  EdgeKey() = default;
  EdgeKey(int u, int v) : a(std::min(u, v)), b(std::max(u, v)) {}
  auto operator<=>(const EdgeKey&) const = default;
};

struct EdgeKeyHash {
  std::size_t operator()(const EdgeKey& e) const noexcept {
    return std::hash<std::uint64_t>{}((static_cast<std::uint64_t>(static_cast<std::uint32_t>(e.a)) << 32) |
                                      static_cast<std::uint32_t>(e.b));
  }
};

struct RemeshVertex {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  VertexKind kind = VertexKind::surface;
  GeometryPoint on;  ///< its CAD entity and parametric coordinates (on.x == x)
  /// The unit patch normal at x for every patch of its triangles (one entry for a
  /// surface vertex; one per side for a vertex on a feature curve).
  std::vector<std::pair<int, Eigen::Vector3d>> normals;
  /// The normal on `patch` (zero if the vertex has no triangle there).
  Eigen::Vector3d normal(int patch) const {
    for (const auto& [p, n] : normals)
      if (p == patch) return n;
    return Eigen::Vector3d::Zero();
  }
};

struct RemeshTriangle {
  std::array<int, 3> v{0, 0, 0};  ///< counter-clockwise about the patch normal
  int patch = 0;
  bool alive = true;
};

class RemeshMesh {
 public:
  std::vector<RemeshVertex> vertices;
  std::vector<RemeshTriangle> triangles;
  /// Feature edges: key(a, b) -> the feature curve they lie on.
  std::unordered_map<EdgeKey, int, EdgeKeyHash> feature_edges;

  static EdgeKey key(int a, int b) { return {a, b}; }
  int add_vertex(const RemeshVertex& v);
  int add_triangle(const RemeshTriangle& t);
  void kill_triangle(int t);
  /// Replaces the corners of live triangle t (incidence updated).
  void set_triangle(int t, const std::array<int, 3>& v);
  /// Rebuilds the incidence from `triangles` (after filling them directly).
  void rebuild_incidence();

  const std::vector<int>& triangles_of(int v) const { return incident_[v]; }
  /// Live triangles that contain both a and b.
  std::vector<int> edge_triangles(int a, int b) const;
  bool has_edge(int a, int b) const;
  bool is_feature(int a, int b) const { return feature_edges.count(key(a, b)) > 0; }
  int feature_curve(int a, int b) const;
  /// Calls f(t) for each live triangle t that contains both a and b (no allocation).
  template <class F>
  void for_each_edge_triangle(int a, int b, F&& f) const {
    for (int t : incident_[a]) {
      const auto& v = triangles[t].v;
      if (v[0] == b || v[1] == b || v[2] == b) f(t);
    }
  }
  /// Vertices joined to v by an edge.
  std::vector<int> neighbours(int v) const;
  /// The same into `out` (cleared first; no allocation once it has grown).
  void neighbours(int v, std::vector<int>& out) const;
  /// Every edge (a < b) of the live triangles, once.
  std::vector<std::array<int, 2>> edges() const;
  std::size_t live_triangles() const;
  std::size_t live_vertices() const;

  /// Removes dead triangles and unreferenced vertices (indices change).
  void compact();
  /// V - E + F of the live triangles of each patch (patch -> chi).
  std::map<int, long> euler_characteristics() const;
  /// Edges with more than two triangles, or whose two triangles traverse it in
  /// the same direction (inconsistent orientation): 0 for an oriented manifold.
  std::size_t non_manifold_edges() const;

 private:
  std::vector<std::vector<int>> incident_;
};

}  // namespace meshopt
