// The Gmsh model for the remesher of Dassi et al. 2014 (Sect. 4): patches,
// feature curves, closest-point projections, mesh conversion (Gmsh 4.8 API).
#include "meshopt/gmsh/gmsh_remesh_model.h"

#include <gmsh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <unordered_map>

#include "gmsh_elements.h"
#include "gmsh_util.h"
#include "meshopt/flip_energy.h"
#include "meshopt/gmsh/gmsh_mesh.h"
#include "meshopt/remesh_statistics.h"
#include "toolkit/union_find.h"

namespace meshopt::gmsh_io {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Vector3d vec3(const std::vector<double>& v, std::size_t i = 0) { return {v[3 * i], v[3 * i + 1], v[3 * i + 2]}; }

/// The closest point of entity (dim, tag) to x and its parametric coordinates.
/// (Gmsh 4.8's getClosestPoint leaves the parametric coordinates unset for OCC
/// entities: they come from getParametrization of the closest point.)
/// Not-a-number point and parameters where Gmsh fails (its inverse mapping may
/// not converge far from the entity): callers then skip the candidate or
/// reject the operation.
std::pair<Eigen::Vector3d, Eigen::Vector2d> closest_point(int dim, int tag, const Eigen::Vector3d& x) {
  std::vector<double> c, p;
  try {
    gmsh::model::getClosestPoint(dim, tag, {x.x(), x.y(), x.z()}, c, p);
    gmsh::model::getParametrization(dim, tag, c, p);
    return {vec3(c), Eigen::Vector2d(p.at(0), dim == 2 ? p.at(1) : 0.0)};
  } catch (...) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {Eigen::Vector3d::Constant(nan), Eigen::Vector2d::Constant(nan)};
  }
}

/// The foot point on `face` of x by Gauss-Newton from uv (the parameters of a
/// nearby mesh vertex): uv += (J^T J)^-1 J^T (x - phi(uv)), J = (phi_u, phi_v),
/// until the tangential step is below tol. A local closest point, at a few
/// evaluations of phi and its first derivatives instead of OCC's global
/// extremum search and inverse mapping. Empty if it leaves the parameter box
/// (a periodic face's seam, a face's end) or does not converge in 8 steps.
std::optional<Eigen::Vector2d> local_foot(const GmshFace& face, Eigen::Vector2d uv, const Eigen::Vector3d& x,
                                          double tol) {
  for (int it = 0; it < 8; ++it) {
    const SurfacePoint p = face.evaluate(uv, 1);
    const Eigen::Matrix2d jtj = p.d.transpose() * p.d;
    if (!(std::abs(jtj.determinant()) > 1e-14 * jtj.squaredNorm())) return std::nullopt;  // degenerate point
    const Eigen::Vector2d step = jtj.inverse() * (p.d.transpose() * (x - p.x));
    uv += step;
    if (!uv.allFinite() || (uv.array() < face.lower().array()).any() || (uv.array() > face.upper().array()).any())
      return std::nullopt;
    if ((p.d * step).norm() <= tol) return uv;
  }
  return std::nullopt;
}

/// (u, v) on `face` of point x = the point `tag` (dim 0) or curve `tag` at t
/// (dim 1) of its boundary: Gmsh's reparametrization (OCC's closest point is
/// unreliable exactly on a face's boundary), the closest point if that fails.
Eigen::Vector2d uv_of_boundary_point(const GmshFace& face, int dim, int tag, double t, const Eigen::Vector3d& x,
                                     double tol) {
  try {
    std::vector<double> uv;
    gmsh::model::reparametrizeOnSurface(dim, tag, dim == 1 ? std::vector<double>{t} : std::vector<double>{},
                                        face.tag(), uv);
    const Eigen::Vector2d u(uv.at(0), uv.at(1));
    if ((face.value(u) - x).norm() <= tol) return u;
  } catch (...) {
  }
  return closest_point(2, face.tag(), x).second;
}


/// +1 if Gmsh's triangles of `face` turn counter-clockwise about phi_u x phi_v, -1 if clockwise.
int face_orientation(const GmshFace& face) {
  std::vector<std::size_t> tags, nodes;
  std::vector<double> xyz, uv;
  gmsh::model::mesh::getNodes(tags, xyz, uv, 2, face.tag(), true, true);
  if (uv.size() != 2 * tags.size())
    throw InputError(cat("the mesh has no parametric coordinates on surface ", face.tag(),
                         " (save it with Mesh.SaveParametric = 1)"));
  std::unordered_map<std::size_t, std::size_t> index;
  for (std::size_t i = 0; i < tags.size(); ++i) index[tags[i]] = i;
  std::vector<std::size_t> elems;
  gmsh::model::mesh::getElementsByType(2, elems, nodes, face.tag());
  long balance = 0;
  for (std::size_t e = 0; e < elems.size() && e < 200; ++e) {
    std::array<Eigen::Vector3d, 3> x;
    for (int k = 0; k < 3; ++k) x[k] = vec3(xyz, index.at(nodes[3 * e + k]));
    const std::size_t i0 = index.at(nodes[3 * e]);
    const Eigen::Vector3d n = unit_normal(face.evaluate({uv[2 * i0], uv[2 * i0 + 1]}, 1));
    const double d = triangle_normal(x[0], x[1], x[2]).dot(n);
    if (d != 0.0) balance += d > 0.0 ? 1 : -1;
  }
  return balance >= 0 ? 1 : -1;
}

}  // namespace

bool CadFeatures::is_feature(int curve) const {
  return std::binary_search(feature_curves.begin(), feature_curves.end(), curve);
}
bool CadFeatures::is_corner(int point) const { return std::binary_search(corners.begin(), corners.end(), point); }

GmshRemeshGeometry::GmshRemeshGeometry(CadFeatures features) : f_(std::move(features)) {
  for (const auto& [tag, patch] : f_.patch_of_face) faces_[tag] = std::make_unique<GmshFace>(tag);
}

const GmshFace& GmshRemeshGeometry::face(int tag) const { return *faces_.at(tag); }

Eigen::Vector3d GmshRemeshGeometry::face_normal(int tag, const Eigen::Vector2d& uv) const {
  const GmshFace& f = face(tag);
  Eigen::Vector3d n = unit_normal(f.evaluate(uv, 1));
  // At a degenerate point (a pole) the normal is the limit from inside the face.
  for (double t = 1e-7; n.isZero() && t < 0.1; t *= 10.0)
    n = unit_normal(f.evaluate(uv + t * (0.5 * (f.lower() + f.upper()) - uv), 1));
  return f_.face_sign.at(tag) * n;
}

namespace {

// The model's faces that carry mesh triangles, sorted. \throw InputError for
// elements other than linear triangles, or no triangles at all.
std::vector<int> triangulated_faces() {
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  std::vector<int> face_tags;
  for (const auto& [dim, tag] : faces)
    if (face_elements(tag, {2}, "remeshing needs linear triangles (type 2)").count > 0)
      face_tags.push_back(tag);
  if (face_tags.empty()) throw InputError("the mesh has no triangles on the model's surfaces");
  std::sort(face_tags.begin(), face_tags.end());
  return face_tags;
}

// The dihedral angle across `curve`: the largest angle between the oriented
// normals of its two faces at five points along it; pi for a curve of one face
// side or of more than two (a boundary, non-manifold); nullopt for a curve
// that is a point (an OCC sphere's pole).
std::optional<double> curve_dihedral(int curve, const std::vector<int>& fs,
                                     const std::map<int, std::unique_ptr<GmshFace>>& gf, const CadFeatures& f) {
  std::vector<double> lo, hi;
  gmsh::model::getParametrizationBounds(1, curve, lo, hi);
  std::vector<Eigen::Vector3d> xs;
  std::vector<double> ts;
  for (int k = 1; k <= 5; ++k) {
    std::vector<double> x;
    ts.push_back(lo[0] + (hi[0] - lo[0]) * k / 6.0);
    gmsh::model::getValue(1, curve, {ts.back()}, x);
    xs.push_back(vec3(x));
  }
  double extent = 0.0;
  for (const auto& x : xs) extent = std::max(extent, (x - xs.front()).norm());
  if (!(extent > 1e-9 * f.diagonal)) return std::nullopt;
  if (fs.size() != 2) return std::numbers::pi;
  double dihedral = 0.0;
  for (std::size_t k = 0; k < xs.size(); ++k) {
    std::array<Eigen::Vector3d, 2> n;
    for (int side = 0; side < 2; ++side) {
      const GmshFace& face = *gf.at(fs[side]);
      n[side] = f.face_sign.at(fs[side]) *
                unit_normal(face.evaluate(uv_of_boundary_point(face, 1, curve, ts[k], xs[k], 1e-7 * f.diagonal), 1));
    }
    dihedral = std::max(dihedral, std::acos(std::clamp(n[0].dot(n[1]), -1.0, 1.0)));
  }
  return dihedral;
}

// The patches: faces joined across smooth curves (union-find over face_tags'
// positions), numbered in order of first face.
void group_into_patches(CadFeatures& f, const std::vector<int>& face_tags, toolkit::UnionFind& smoothly_joined) {
  for (int tag : face_tags) {
    bool smooth = false;
    for (int c : f.face_curves[tag]) {
      const std::vector<int>& fs = f.curve_faces[c];
      smooth = smooth || (!f.is_feature(c) && fs.size() == 2 && fs[0] != fs[1]);  // a junction, not a seam
    }
    f.smooth_boundary[tag] = smooth;
  }
  std::map<int, int> patch_of_root;
  for (std::size_t i = 0; i < face_tags.size(); ++i) {
    const int root = static_cast<int>(smoothly_joined.find(i));
    const auto [it, inserted] = patch_of_root.emplace(root, static_cast<int>(f.patch_faces.size()));
    if (inserted) f.patch_faces.emplace_back();
    f.patch_faces[it->second].push_back(face_tags[i]);
    f.patch_of_face[face_tags[i]] = it->second;
  }
}

// The model's points: corners where a feature curve ends, and the faces at each.
void find_corners(CadFeatures& f) {
  std::set<int> corners;
  for (const auto& [curve, fs] : f.curve_faces) {
    std::vector<int> up, down;
    gmsh::model::getAdjacencies(1, curve, up, down);
    for (int p : down) {
      if (f.is_feature(curve)) corners.insert(p);
      for (int face : fs)
        if (std::find(f.point_faces[p].begin(), f.point_faces[p].end(), face) == f.point_faces[p].end())
          f.point_faces[p].push_back(face);
    }
  }
  f.corners.assign(corners.begin(), corners.end());
}

}  // namespace

CadFeatures detect_features(double feature_angle) {
  CadFeatures f;
  double box[6];
  gmsh::model::getBoundingBox(-1, -1, box[0], box[1], box[2], box[3], box[4], box[5]);
  f.diagonal = Eigen::Vector3d(box[3] - box[0], box[4] - box[1], box[5] - box[2]).norm();
  const std::vector<int> face_tags = triangulated_faces();
  std::map<int, std::unique_ptr<GmshFace>> gf;
  for (int tag : face_tags) {
    gf[tag] = std::make_unique<GmshFace>(tag);
    f.face_sign[tag] = face_orientation(*gf[tag]);
    gmsh::vectorpair bnd;
    gmsh::model::getBoundary({{2, tag}}, bnd, false, true, false);
    for (const auto& [d, c] : bnd) {
      f.curve_faces[std::abs(c)].push_back(tag);
      f.face_curves[tag].push_back(std::abs(c));
    }
  }
  // Features: sharp curves, curves of one face side (boundaries), non-manifold
  // curves; faces across the other curves are one patch.
  toolkit::UnionFind smoothly_joined(face_tags.size());
  auto index_of = [&](int tag) {
    return static_cast<std::size_t>(std::lower_bound(face_tags.begin(), face_tags.end(), tag) - face_tags.begin());
  };
  for (const auto& [curve, fs] : f.curve_faces) {
    const std::optional<double> dihedral = curve_dihedral(curve, fs, gf, f);
    f.curve_dihedral[curve] = dihedral.value_or(0.0);
    if (!dihedral) continue;
    if (fs.size() != 2 || *dihedral > feature_angle)
      f.feature_curves.push_back(curve);
    else if (fs[0] != fs[1])
      smoothly_joined.unite(index_of(fs[0]), index_of(fs[1]));
  }
  std::sort(f.feature_curves.begin(), f.feature_curves.end());
  group_into_patches(f, face_tags, smoothly_joined);
  find_corners(f);
  return f;
}

GeometryPoint GmshRemeshGeometry::project_to_patch(int patch, const Eigen::Vector3d& x,
                                                   const ProjectionHint& hint) const {
  // Candidates: the hint's faces of the patch and their neighbours in it (a point
  // near a smooth junction may belong to the face on the other side).
  std::vector<int> cand;
  auto add = [&](int face) {
    const auto it = f_.patch_of_face.find(face);
    if (it != f_.patch_of_face.end() && it->second == patch && std::find(cand.begin(), cand.end(), face) == cand.end())
      cand.push_back(face);
  };
  for (int face : hint.faces) {
    add(face);
    for (int c : f_.face_curves.at(face))
      if (!f_.is_feature(c))
        for (int g : f_.curve_faces.at(c)) add(g);
  }
  if (cand.empty()) cand = f_.patch_faces.at(patch);
  // The usual case, a short move on one face: the local foot point from the
  // nearest hint corner on that face, accepted where the hint's triangles prove
  // it inside the trimmed face (then no other face of the smooth patch is nearer
  // for a move within the star).
  for (int fc : hint.faces) {
    if (std::find(cand.begin(), cand.end(), fc) == cand.end()) continue;
    const GeometryPoint* start = nullptr;
    for (const auto& t : hint.triangles)
      for (const GeometryPoint& c : t)
        if (c.entity == fc && (!start || (c.x - x).squaredNorm() < (start->x - x).squaredNorm())) start = &c;
    if (!start) continue;
    const GmshFace& gf = face(fc);
    const auto uv = local_foot(gf, start->param, x, 1e-10 * f_.diagonal);
    if (uv && hint.proves_inside(fc, *uv, 0.5 * (gf.upper() - gf.lower()), f_.smooth_boundary.at(fc)))
      return {gf.value(*uv), fc, *uv};
  }
  // Closest points on the untrimmed faces, nearest first; the first inside its
  // trimmed face wins (the hint's mesh triangles spare most exact tests).
  std::vector<std::pair<double, GeometryPoint>> found;
  for (int face : cand) {
    const auto [y, uv] = closest_point(2, face, x);
    if (y.allFinite()) found.push_back({(y - x).norm(), GeometryPoint{y, face, uv}});
  }
  std::sort(found.begin(), found.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
  GeometryPoint best{Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()), -1, Eigen::Vector2d::Zero()};
  double best_d = kInf;
  for (const auto& [d, p] : found)
    if (hint.proves_inside(p.entity, p.param, 0.5 * (face(p.entity).upper() - face(p.entity).lower()),
                           f_.smooth_boundary.at(p.entity)) ||
        face(p.entity).contains_exactly(p.param)) {
      best_d = d;
      best = p;
      break;
    }
  if (best_d < kInf) return best;
  // x projects onto a trimmed-away part of every candidate: its closest point is
  // then on a boundary curve of one of them.
  for (int face : cand)
    for (int c : f_.face_curves.at(face)) {
      const auto [y, t] = closest_point(1, c, x);
      const double d = (y - x).norm();
      if (d < best_d) {
        best_d = d;
        best = {y, face, uv_of_boundary_point(this->face(face), 1, c, t.x(), y, 1e-7 * f_.diagonal)};
      }
    }
  return best;
}

Eigen::Vector2d GmshRemeshGeometry::boundary_uv(int face, VertexKind kind, const GeometryPoint& p) const {
  return uv_of_boundary_point(this->face(face), kind == VertexKind::curve ? 1 : 0, p.entity, p.param.x(), p.x,
                              1e-7 * f_.diagonal);
}

GeometryPoint GmshRemeshGeometry::project_to_curve(int curve, const Eigen::Vector3d& x) const {
  const auto [y, t] = closest_point(1, curve, x);
  return {y, curve, t};
}

GeometryPoint GmshRemeshGeometry::curve_midpoint(int curve, VertexKind ka, const GeometryPoint& a, VertexKind kb,
                                               const GeometryPoint& b) const {
  // Curve parameters of the end points (a corner's by projection).
  auto param = [&](VertexKind k, const GeometryPoint& p) {
    return k == VertexKind::curve && p.entity == curve ? p.param.x() : closest_point(1, curve, p.x).second.x();
  };
  const double ta = param(ka, a), tb = param(kb, b);
  std::vector<double> lo, hi;
  gmsh::model::getParametrizationBounds(1, curve, lo, hi);
  if (!std::isfinite(ta) || !std::isfinite(tb) || lo.empty() || hi.empty()) return project_to_curve(curve, 0.5 * (a.x + b.x));
  const double period = hi[0] - lo[0];
  // Sample the arc t(l) = ta + l (tb - ta) and, on a closed curve, the arc
  // through its seam; keep the shorter; the arc-length midpoint by linear
  // interpolation of the cumulative chord length over kSamples pieces.
  constexpr int kSamples = 16;
  std::vector<double> ends;
  gmsh::model::getValue(1, curve, {lo[0], hi[0]}, ends);
  const bool closed = (vec3(ends, 0) - vec3(ends, 1)).norm() <= 1e-9 * f_.diagonal;
  std::vector<double> deltas{tb - ta};
  if (closed && tb != ta) deltas.push_back(tb - ta - std::copysign(period, tb - ta));
  auto wrap = [&](double t) { return closed ? lo[0] + std::fmod(std::fmod(t - lo[0], period) + period, period) : t; };
  GeometryPoint best;
  double best_length = kInf;
  for (double delta : deltas) {
    std::vector<double> ts, xs;
    for (int k = 0; k <= kSamples; ++k) ts.push_back(wrap(ta + delta * k / kSamples));
    try {
      gmsh::model::getValue(1, curve, ts, xs);
    } catch (...) {
      continue;
    }
    std::vector<double> cumulative{0.0};
    for (int k = 1; k <= kSamples; ++k) cumulative.push_back(cumulative.back() + (vec3(xs, k) - vec3(xs, k - 1)).norm());
    if (!(cumulative.back() < best_length)) continue;
    best_length = cumulative.back();
    const double half = 0.5 * cumulative.back();
    int k = 1;
    while (k < kSamples && cumulative[k] < half) ++k;
    const double piece = cumulative[k] - cumulative[k - 1];
    const double w = piece > 0.0 ? (half - cumulative[k - 1]) / piece : 0.0;
    const double t = wrap(ta + delta * (k - 1 + w) / kSamples);
    std::vector<double> x;
    gmsh::model::getValue(1, curve, {t}, x);
    best = {vec3(x), curve, Eigen::Vector2d(t, 0.0)};
  }
  if (!(best_length < kInf)) return project_to_curve(curve, 0.5 * (a.x + b.x));
  return best;
}

Eigen::Vector3d GmshRemeshGeometry::patch_normal(int patch, VertexKind kind, const GeometryPoint& p) const {
  if (kind == VertexKind::surface) return face_normal(p.entity, p.param);
  const std::vector<int>& around = kind == VertexKind::curve ? f_.curve_faces.at(p.entity) : f_.point_faces.at(p.entity);
  for (int face : around)
    if (f_.patch_of_face.at(face) == patch) return face_normal(face, boundary_uv(face, kind, p));
  return Eigen::Vector3d::Zero();
}

namespace {

// The reading of the session's triangles into a RemeshMesh: vertices
// classified by the model entity Gmsh put each node on, normals per patch,
// feature edges.
class RemeshMeshReader {
 public:
  explicit RemeshMeshReader(const GmshRemeshGeometry& g) : g_(g), f_(g.features()) {}

  RemeshMesh read() {
    read_triangle_nodes();
    for (int dim = 0; dim <= 2; ++dim) add_vertices_on(dim);
    add_triangles();
    add_normals();
    mark_feature_edges();
    return std::move(m_);
  }

 private:
  // Gmsh's triangles turn counter-clockwise about the oriented normal
  // face_sign * phi_u x phi_v by the definition of face_sign.
  void read_triangle_nodes() {
    for (const auto& [face, patch] : f_.patch_of_face) {
      std::vector<std::size_t> elems, nodes;
      gmsh::model::mesh::getElementsByType(2, elems, nodes, face);
      for (std::size_t e = 0; e < elems.size(); ++e) {
        const std::array<std::size_t, 3> n{nodes[3 * e], nodes[3 * e + 1], nodes[3 * e + 2]};
        tri_nodes_.push_back(n);
        tri_patch_.push_back(patch);
        for (std::size_t k : n) face_of_node_.emplace(k, face);
      }
    }
  }

  // The vertices of the nodes on the entities of dimension `dim` that some triangle uses.
  void add_vertices_on(int dim) {
    gmsh::vectorpair ents;
    gmsh::model::getEntities(ents, dim);
    for (const auto& [d, tag] : ents) {
      std::vector<std::size_t> tags;
      std::vector<double> xyz, par;
      gmsh::model::mesh::getNodes(tags, xyz, par, dim, tag, false, true);
      for (std::size_t i = 0; i < tags.size(); ++i) {
        const auto fn = face_of_node_.find(tags[i]);
        if (fn == face_of_node_.end()) continue;  // not on a triangle
        index_[tags[i]] = m_.add_vertex(vertex(dim, tag, tags, xyz, par, i, fn->second));
      }
    }
  }

  // Node i of entity (dim, tag): a corner, a vertex on a feature curve, a
  // surface vertex of its face, or, on a smooth curve or point, a surface
  // vertex of `face`, a face it touches.
  RemeshVertex vertex(int dim, int tag, const std::vector<std::size_t>& tags, const std::vector<double>& xyz,
                      const std::vector<double>& par, std::size_t i, int face) const {
    RemeshVertex v;
    v.x = vec3(xyz, i);
    if (dim == 0 && f_.is_corner(tag)) {
      v.kind = VertexKind::corner;
      v.on = {v.x, tag, Eigen::Vector2d::Zero()};
    } else if (dim == 1 && f_.is_feature(tag)) {
      if (par.size() != tags.size()) throw InputError(cat("the mesh has no parametric coordinates on curve ", tag));
      v.kind = VertexKind::curve;
      v.on = {v.x, tag, Eigen::Vector2d(par[i], 0.0)};
    } else if (dim == 2) {
      if (par.size() != 2 * tags.size())
        throw InputError(cat("the mesh has no parametric coordinates for the nodes inside surface ", tag,
                             " (save it with Mesh.SaveParametric = 1)"));
      v.on = {v.x, tag, Eigen::Vector2d(par[2 * i], par[2 * i + 1])};
    } else {
      const GeometryPoint on{v.x, tag, Eigen::Vector2d(dim == 1 && !par.empty() ? par[i] : 0.0, 0.0)};
      v.on = {v.x, face, g_.boundary_uv(face, dim == 1 ? VertexKind::curve : VertexKind::corner, on)};
    }
    return v;
  }

  void add_triangles() {
    for (std::size_t t = 0; t < tri_nodes_.size(); ++t) {
      RemeshTriangle tr{{0, 0, 0}, tri_patch_[t], true};
      for (int k = 0; k < 3; ++k) {
        const auto it = index_.find(tri_nodes_[t][k]);
        if (it == index_.end())
          throw InputError(cat("triangle node ", tri_nodes_[t][k], " is not classified on the model"));
        tr.v[k] = it->second;
      }
      m_.add_triangle(tr);
    }
  }

  // Normals of every vertex on each patch of its triangles.
  void add_normals() {
    for (std::size_t v = 0; v < m_.vertices.size(); ++v)
      for (int t : m_.triangles_of(static_cast<int>(v))) {
        RemeshVertex& vv = m_.vertices[v];
        const int p = m_.triangles[t].patch;
        if (vv.normal(p).isZero()) vv.normals.emplace_back(p, g_.patch_normal(p, vv.kind, vv.on));
      }
  }

  // Feature edges: Gmsh's line elements on feature curves, else triangle edges
  // whose end points are both on the same feature curve (or its corners).
  void mark_feature_edges() {
    for (int curve : f_.feature_curves) {
      std::vector<std::size_t> elems, nodes;
      gmsh::model::mesh::getElementsByType(1, elems, nodes, curve);
      for (std::size_t e = 0; e < elems.size(); ++e) {
        const auto a = index_.find(nodes[2 * e]), b = index_.find(nodes[2 * e + 1]);
        if (a != index_.end() && b != index_.end() && m_.has_edge(a->second, b->second))
          m_.feature_edges[RemeshMesh::key(a->second, b->second)] = curve;
      }
    }
    if (!m_.feature_edges.empty() || f_.feature_curves.empty()) return;
    for (const auto& [a, b] : m_.edges()) {
      const RemeshVertex &va = m_.vertices[a], &vb = m_.vertices[b];
      if (va.kind == VertexKind::curve && vb.kind != VertexKind::surface &&
          (vb.kind == VertexKind::corner || vb.on.entity == va.on.entity))
        m_.feature_edges[RemeshMesh::key(a, b)] = va.on.entity;
      else if (vb.kind == VertexKind::curve && va.kind == VertexKind::corner)
        m_.feature_edges[RemeshMesh::key(a, b)] = vb.on.entity;
    }
  }

  const GmshRemeshGeometry& g_;
  const CadFeatures& f_;
  RemeshMesh m_;
  std::unordered_map<std::size_t, int> index_;         // node tag -> vertex
  std::unordered_map<std::size_t, int> face_of_node_;  // node tag -> a face of a triangle using it
  std::vector<int> tri_patch_;
  std::vector<std::array<std::size_t, 3>> tri_nodes_;
};

}  // namespace

RemeshMesh read_remesh_mesh(const GmshRemeshGeometry& g) { return RemeshMeshReader(g).read(); }

CentroidProjection project_centroids(const RemeshMesh& m, const GmshRemeshGeometry& g) {
  CentroidProjection out;
  for (const RemeshTriangle& t : m.triangles) {
    if (!t.alive) {
      out.face.push_back(-1);
      out.distance.push_back(0.0);
      out.on.push_back({});
      continue;
    }
    ProjectionHint hint;
    std::vector<int>& near = hint.faces;
    for (int v : t.v)
      if (m.vertices[v].kind == VertexKind::surface) near.push_back(m.vertices[v].on.entity);
    const Eigen::Vector3d c = (m.vertices[t.v[0]].x + m.vertices[t.v[1]].x + m.vertices[t.v[2]].x) / 3.0;
    if (near.empty())  // all corners on curves: the faces of the patch around them
      for (int v : t.v)
        for (int face : m.vertices[v].kind == VertexKind::curve ? g.features().curve_faces.at(m.vertices[v].on.entity)
                                                                 : g.features().point_faces.at(m.vertices[v].on.entity))
          near.push_back(face);
    const GeometryPoint p = g.project_to_patch(t.patch, c, hint);
    out.face.push_back(p.entity);
    out.distance.push_back((p.x - c).norm());
    out.on.push_back(p);
  }
  return out;
}

CurvatureAlignment curvature_alignment(const RemeshMesh& m, const CentroidProjection& c) {
  CurvatureAlignment out;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const RemeshTriangle& tr = m.triangles[t];
    if (!tr.alive) continue;
    std::vector<double> kmax, kmin, dmax, dmin;
    gmsh::model::getPrincipalCurvatures(c.on[t].entity, {c.on[t].param.x(), c.on[t].param.y()}, kmax, kmin, dmax, dmin);
    const bool max_is_high = std::abs(kmax.at(0)) >= std::abs(kmin.at(0));
    const Eigen::Vector3d low = vec3(max_is_high ? dmin : dmax);
    const std::array<Eigen::Vector3d, 3> x{m.vertices[tr.v[0]].x, m.vertices[tr.v[1]].x, m.vertices[tr.v[2]].x};
    const Eigen::Vector3d n = triangle_normal(x[0], x[1], x[2]);
    Eigen::Vector3d axis = long_axis(x[0], x[1], x[2]);
    axis -= axis.dot(n) * n;
    Eigen::Vector3d dir = low - low.dot(n) * n;
    const double cosine = axis.norm() > 0.0 && dir.norm() > 0.0 ? std::abs(axis.normalized().dot(dir.normalized())) : 1.0;
    out.kappa_low.push_back(max_is_high ? kmin[0] : kmax[0]);
    out.kappa_high.push_back(max_is_high ? kmax[0] : kmin[0]);
    out.angle_degrees.push_back(std::acos(std::min(1.0, cosine)) * 180.0 / std::numbers::pi);
  }
  return out;
}

void write_remesh_mesh(const std::string& path, const RemeshMesh& m, const std::vector<int>& faces) {
  gmsh::model::mesh::clear();
  // Nodes by entity (tags 1..N in vertex order).
  std::map<std::pair<int, int>, std::pair<std::vector<std::size_t>, std::pair<std::vector<double>, std::vector<double>>>>
      by_entity;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    const RemeshVertex& vv = m.vertices[v];
    const int dim = vv.kind == VertexKind::corner ? 0 : vv.kind == VertexKind::curve ? 1 : 2;
    auto& [tags, data] = by_entity[{dim, vv.on.entity}];
    tags.push_back(v + 1);
    data.first.insert(data.first.end(), {vv.x.x(), vv.x.y(), vv.x.z()});
    if (dim >= 1) data.second.push_back(vv.on.param.x());
    if (dim == 2) data.second.push_back(vv.on.param.y());
  }
  std::map<int, std::vector<std::size_t>> tri_by_face, line_by_curve;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    if (!m.triangles[t].alive) continue;
    for (int v : m.triangles[t].v) tri_by_face[faces[t]].push_back(static_cast<std::size_t>(v) + 1);
  }
  for (const auto& [k, curve] : m.feature_edges) {
    line_by_curve[curve].push_back(static_cast<std::size_t>(k.a) + 1);
    line_by_curve[curve].push_back(static_cast<std::size_t>(k.b) + 1);
  }
  try {
    for (const auto& [ent, nodes] : by_entity)
      gmsh::model::mesh::addNodes(ent.first, ent.second, nodes.first, nodes.second.first, nodes.second.second);
    for (const auto& [curve, nodes] : line_by_curve) gmsh::model::mesh::addElementsByType(curve, 1, {}, nodes);
    for (const auto& [face, nodes] : tri_by_face) gmsh::model::mesh::addElementsByType(face, 2, {}, nodes);
  } catch (...) {
    throw IoError(cat("cannot store the remeshed surface in the Gmsh model: ", gmsh_error()));
  }
  write_current_mesh(path);
}

}  // namespace meshopt::gmsh_io
