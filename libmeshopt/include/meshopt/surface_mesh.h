#pragma once
// A triangle or quadrilateral mesh whose nodes live on parameterized faces
// (Gargallo-Peiro Sect. 3): physical positions of all nodes, parametric
// coordinates of the free ones (inside faces), and for each element corner its
// parametric coordinates on the element's face (used for the surface normal that
// orients the element, Sect. 3.2). Nodes on CAD edges and vertices are fixed.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <span>
#include <vector>

#include "meshopt/surface.h"
#include "meshopt/surface_measure.h"

namespace meshopt {

struct SurfaceElement {
  std::array<int, 4> v{0, 0, 0, 0};  ///< node indices, counter-clockwise w.r.t. the face normal
  int nv = 3;                        ///< 3 (triangle) or 4 (quadrilateral)
  int face = 0;                      ///< index into SurfaceMesh::faces
};

struct SurfaceMesh {
  std::vector<const ParametricSurface*> faces;  ///< not owned
  std::vector<SurfaceElement> elements;
  std::vector<Eigen::Vector3d> x;  ///< physical positions of all nodes
  std::vector<Eigen::Vector2d> u;  ///< parametric coordinates (used for free nodes)
  std::vector<int> free_face;      ///< face of a free node, -1 for a fixed node
  /// Parametric coordinates of element e's corner i on its face at corner_uv[4 e + i];
  /// may be left empty when every node has a valid u on the element's face (one-face meshes).
  std::vector<Eigen::Vector2d> corner_uv;
};

/// Ideal element size at a physical point (Sect. 4.3, SETIDEALELEMENTS).
using SizeField = std::function<double(const Eigen::Vector3d&)>;

/// The corner triangles of an element (Sect. 3.5, Fig. 3): element-local vertex
/// triples (corner, next, previous), their ideal vertices for ideal size h, and the
/// weight of each triangle in the element's distortion (1, or 1/4 for quads).
struct CornerTriangle {
  std::array<int, 3> local{0, 1, 2};
  std::array<Eigen::Vector2d, 3> ideal;
  double weight = 1.0;
};
std::vector<CornerTriangle> corner_triangles(int nv, double h);

/// Checks the mesh: sizes, indices, faces, free nodes inside their face's
/// domain with phi(u) = x, non-degenerate surface normals at every corner.
/// `exact_domain` false: the cheap domain test only (ParametricSurface::contains,
/// not the trimmed face), for callers that only measure the mesh.
/// \throw toolkit::InputError (a std::invalid_argument) naming the first problem (node, element, face).
void validate_surface_mesh(const SurfaceMesh& mesh, bool exact_domain = true);

/// Unit surface normal at each element corner (4 per element); zero at a fixed
/// node on a degenerate point (e.g. a pole that is a CAD vertex).
/// \throw toolkit::InputError (a std::invalid_argument) at a degenerate point under a free node.
std::vector<Eigen::Vector3d> corner_normals(const SurfaceMesh& mesh);

/// Per-element quality 1/eta (delta = 0; quads: 1 / mean of the four corner
/// distortions, Definitions 3-4) and validity (every corner triangle sigma > 0).
/// `node_size` is the ideal size per node (ignored by the shape measure; empty = 1).
struct ElementQualities {
  std::vector<double> quality;  ///< 0 for invalid elements
  std::vector<char> valid;
  std::size_t tangled = 0;
  double min = 0.0, max = 0.0, mean = 0.0, stddev = 0.0;
};
ElementQualities element_qualities(const SurfaceMesh& mesh, std::span<const Eigen::Vector3d> normals,
                                   SurfaceMeasure measure, std::span<const double> node_size);

/// The size field sampled at the nodes; without a field, the mean edge length of
/// the mesh for every node (the "size of the initial mesh", Sect. 4.4).
std::vector<double> node_sizes(const SurfaceMesh& mesh, const SizeField& size);

}  // namespace meshopt
