#pragma once
// The current Gmsh model as the remesher sees it (Dassi et al. 2014, Sect. 4):
// faces grouped into patches across smooth curves, feature curves (dihedral
// angle above a threshold, or bounding a single face) and their corners;
// projections onto patches and curves by closest point in R^3 (independent of
// the faces' parameterizations; trimmed faces respected); and the conversion of
// the model's surface mesh to and from a RemeshMesh.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "meshopt/gmsh/gmsh_face.h"
#include "meshopt/remesh_mesh.h"

namespace meshopt::gmsh_io {

struct CadFeatures {
  std::map<int, int> patch_of_face;              ///< face tag -> patch index
  std::vector<std::vector<int>> patch_faces;     ///< patch -> its face tags
  std::map<int, std::vector<int>> curve_faces;   ///< curve tag -> faces it bounds (a seam twice)
  std::map<int, std::vector<int>> face_curves;   ///< face tag -> its boundary curves
  std::map<int, std::vector<int>> point_faces;   ///< point tag -> faces around it
  std::map<int, double> curve_dihedral;          ///< largest angle between the normals across a curve (radians)
  std::vector<int> feature_curves;               ///< sorted
  std::vector<int> corners;                      ///< sorted: points of feature curves
  std::map<int, bool> smooth_boundary;           ///< face tag -> has a smooth junction curve (crossed freely)
  std::map<int, int> face_sign;                  ///< +1 / -1: Gmsh's triangles about +/- phi_u x phi_v
  double diagonal = 0.0;                         ///< of the model's bounding box
  bool is_feature(int curve) const;
  bool is_corner(int point) const;
};

/// Feature curves and patches of the current model, which must have a surface
/// mesh (it orients the faces). \throw InputError if a face has no triangles.
CadFeatures detect_features(double feature_angle);

class GmshRemeshGeometry final : public RemeshGeometry {
 public:
  explicit GmshRemeshGeometry(CadFeatures features);
  const CadFeatures& features() const { return f_; }
  GeometryPoint project_to_patch(int patch, const Eigen::Vector3d& x, const ProjectionHint& hint) const override;
  GeometryPoint project_to_curve(int curve, const Eigen::Vector3d& x) const override;
  GeometryPoint curve_midpoint(int curve, VertexKind ka, const GeometryPoint& a, VertexKind kb,
                               const GeometryPoint& b) const override;
  Eigen::Vector3d patch_normal(int patch, VertexKind kind, const GeometryPoint& p) const override;
  /// (u, v) on `face` of a point p of one of its boundary curves (kind curve,
  /// p.param.x() = t) or points (kind corner).
  Eigen::Vector2d boundary_uv(int face, VertexKind kind, const GeometryPoint& p) const;
  /// The oriented unit normal of face `face` at (u, v), nudged off a degenerate point.
  Eigen::Vector3d face_normal(int face, const Eigen::Vector2d& uv) const;

 private:
  const GmshFace& face(int tag) const;
  CadFeatures f_;
  std::map<int, std::unique_ptr<GmshFace>> faces_;
};

/// The model's surface mesh (triangles only) classified for remeshing: nodes on
/// corners fixed, on feature curves sliding, all others on their patch (nodes of
/// smooth curves and points become surface vertices).
/// \throw InputError for quadrangles or nodes without parametric coordinates.
RemeshMesh read_remesh_mesh(const GmshRemeshGeometry& geometry);

/// For each triangle of `mesh`: the face its centroid projects onto and the
/// distance of the centroid from the model (the chordal deviation).
struct CentroidProjection {
  std::vector<int> face;
  std::vector<double> distance;
  std::vector<GeometryPoint> on;
};
CentroidProjection project_centroids(const RemeshMesh& mesh, const GmshRemeshGeometry& geometry);

/// Per live triangle: the principal curvatures at its centroid's projection
/// (|kappa_low| <= |kappa_high|) and the angle in degrees, in [0, 90], between the
/// triangle's long axis (projected on the tangent plane) and the principal
/// direction of least |curvature|, along which the 6D metric stretches triangles.
struct CurvatureAlignment {
  std::vector<double> kappa_low, kappa_high, angle_degrees;
};
CurvatureAlignment curvature_alignment(const RemeshMesh& mesh, const CentroidProjection& centroids);

/// Replaces the model's mesh by `mesh` (nodes on their CAD entities with
/// parametric coordinates, triangles on the faces of `faces`, lines on the
/// feature curves) and writes it as MSH 4.1, atomically. \throw IoError.
void write_remesh_mesh(const std::string& path, const RemeshMesh& mesh, const std::vector<int>& faces);

}  // namespace meshopt::gmsh_io
