#pragma once
// What the remesher (Dassi et al. 2014) asks of the CAD model: points placed on
// it by projection in R^3, never through a face's parameterization, so that
// nodes cross smooth junctions between faces freely (Sect. 4).
//
// The model's faces are grouped into patches: maximal sets of faces joined by
// smooth curves. Feature curves (sharp, or bounding a single face) separate
// patches and stay chains of mesh edges; their end points are fixed corners.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace meshopt {

/// Where a remesh vertex lives on the model.
enum class VertexKind {
  corner,   ///< a CAD point ending feature curves: fixed
  curve,    ///< on a feature curve: moves along it
  surface,  ///< inside a patch: moves on its faces
};

/// A point on the model and its classification: the CAD point, curve or face
/// (by kind) and its parametric coordinates there ((t, 0) on a curve, (u, v) on
/// a face, unused for a corner).
struct GeometryPoint {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  int entity = -1;
  Eigen::Vector2d param = Eigen::Vector2d::Zero();
};

/// What the mesh knows around a point to be projected onto a patch: the CAD
/// faces of nearby vertices (where to look first), and the mesh triangles around
/// it with their corners' classification (entity = the face of a surface
/// vertex, -1 for other vertices; param = its (u, v) there).
struct ProjectionHint {
  std::vector<int> faces;
  std::vector<std::array<GeometryPoint, 3>> triangles;
  /// True if (u, v) on `face` lies in one of the triangles whose corners are all
  /// surface vertices of `face`, spanning less than `max_span` in (u, v) (not
  /// across a periodic face's seam): then it is inside the trimmed face without
  /// an exact test. A face with smooth (non-feature) boundary curves, which the
  /// mesh crosses freely, needs `trimmed_inside` true: (u, v) must then also not
  /// lie within kTrimmingMargin of an edge of those triangles that two of them do
  /// not share, where such a curve could bulge into them.
  bool proves_inside(int face, const Eigen::Vector2d& uv, const Eigen::Vector2d& max_span, bool trimmed_inside) const;
};

class RemeshGeometry {
 public:
  virtual ~RemeshGeometry() = default;
  /// The point of patch `patch` closest to x.
  virtual GeometryPoint project_to_patch(int patch, const Eigen::Vector3d& x, const ProjectionHint& hint) const = 0;
  /// The point of feature curve `curve` closest to x.
  virtual GeometryPoint project_to_curve(int curve, const Eigen::Vector3d& x) const = 0;
  /// The point of feature curve `curve` halfway (by arc length) between its
  /// points a and b, classified as `ka` and `kb` (curve: param.x() is the curve
  /// parameter; corner: an end point of the curve), along the shorter of the
  /// arcs between them: where a feature edge is split. The default projects
  /// the chord's midpoint, which on a strongly bent curve may land on another
  /// branch of it.
  virtual GeometryPoint curve_midpoint(int curve, VertexKind ka, const GeometryPoint& a, VertexKind kb,
                                       const GeometryPoint& b) const {
    (void)ka;
    (void)kb;
    return project_to_curve(curve, 0.5 * (a.x + b.x));
  }
  /// The unit normal of patch `patch` at point p of its closure, classified as
  /// `kind` (a face point, or a point of a curve or corner bounding the patch),
  /// oriented like the patch's triangles (counter-clockwise about it).
  virtual Eigen::Vector3d patch_normal(int patch, VertexKind kind, const GeometryPoint& p) const = 0;
};

}  // namespace meshopt
