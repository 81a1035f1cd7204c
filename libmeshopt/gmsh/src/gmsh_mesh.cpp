// Surface meshes of CAD models through the Gmsh 4.8 C++ API.
#include "meshopt/gmsh/gmsh_mesh.h"

#include <gmsh.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include <Eigen/Geometry>

#include "gmsh_elements.h"
#include "gmsh_util.h"

namespace meshopt::gmsh_io {
namespace fs = std::filesystem;

namespace {

/// Mesh node of node tag `nt`, which is used by an element of face `face` but not
/// classified on that face or its boundary; records its parametric coordinates
/// on `face` (closest point) in `uv_of`. \throw InputError if it is far from the face.
template <class NodeIndex>
int foreign_node(std::size_t nt, int face, NodeIndex& node_index,
                 std::unordered_map<std::size_t, Eigen::Vector2d>& uv_of) {
  std::vector<double> xyz, param, closest, uv;
  try {
    gmsh::model::mesh::getNode(nt, xyz, param);
    gmsh::model::getClosestPoint(2, face, xyz, closest, uv);
    gmsh::model::getParametrization(2, face, closest, uv);  // getClosestPoint leaves uv unset (OCC, Gmsh 4.8)
  } catch (...) {
    throw InputError(cat("element node ", nt, " of surface ", face, ": ", gmsh_error()));
  }
  const Eigen::Vector3d x(xyz.at(0), xyz.at(1), xyz.at(2)), c(closest.at(0), closest.at(1), closest.at(2));
  if (!((x - c).norm() <= 1e-6 * std::max(1.0, x.norm())))
    throw InputError(cat("element node ", nt, " of surface ", face, " is not on that surface (", (x - c).norm(),
                         " away)"));
  uv_of[nt] = Eigen::Vector2d(uv.at(0), uv.at(1));
  return node_index(nt, xyz.data());
}

void require_readable(const std::string& path, const char* what) {
  std::ifstream f(path);
  if (!f) throw InputError(cat("cannot read the ", what, " '", path, "'"));
}

/// Gmsh orients a face's elements by the CAD face's orientation, which may be
/// opposite to phi_u x phi_v (a reversed OCC face); libmeshopt wants them
/// counter-clockwise about phi_u x phi_v. Reverses the node order of the face's
/// elements (from `first`) if most of them are clockwise; a few clockwise elements
/// among counter-clockwise ones are tangled and stay as they are.
void orient_like_the_normal(SurfaceMesh& m, const GmshFace& face, std::size_t first) {
  long long balance = 0;
  for (std::size_t e = first; e < m.elements.size(); ++e) {
    const SurfaceElement& el = m.elements[e];
    const Eigen::Vector3d n = unit_normal(face.evaluate(m.corner_uv[4 * e], 1));
    const Eigen::Vector3d c = (m.x[el.v[1]] - m.x[el.v[0]]).cross(m.x[el.v[el.nv - 1]] - m.x[el.v[0]]);
    balance += c.dot(n) > 0.0 ? 1 : -1;
  }
  if (balance >= 0) return;
  for (std::size_t e = first; e < m.elements.size(); ++e) {
    SurfaceElement& el = m.elements[e];
    std::reverse(el.v.begin() + 1, el.v.begin() + el.nv);
    std::reverse(m.corner_uv.begin() + 4 * e + 1, m.corner_uv.begin() + 4 * e + el.nv);
  }
}

}  // namespace

Session::Session(bool verbose) {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", verbose ? 1 : 0);
  gmsh::option::setNumber("General.Verbosity", verbose ? 5 : 1);
}

Session::~Session() { gmsh::finalize(); }

namespace {

// Loads the file `path` (a `what`) into the session with `load` (gmsh::open or gmsh::merge).
void load_file(const std::string& path, const char* what, void (*load)(const std::string&)) {
  require_readable(path, what);
  try {
    load(path);
  } catch (...) {
    throw InputError(cat("cannot load the ", what, " '", path, "': ", gmsh_error()));
  }
}

}  // namespace

void open_model(const std::string& path) {
  load_file(path, "model", gmsh::open);
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  if (faces.empty()) throw InputError(cat("the model '", path, "' has no surfaces"));
}

void merge_mesh(const std::string& path) { load_file(path, "mesh", gmsh::merge); }

void generate_surface_mesh() {
  try {
    gmsh::model::mesh::generate(2);
  } catch (...) {
    throw InputError(cat("Gmsh could not mesh the model: ", gmsh_error()));
  }
}

namespace {

// The reading of the session's mesh into a GmshSurfaceMesh, face by face.
class SurfaceMeshReader {
 public:
  GmshSurfaceMesh read() {
    gmsh::vectorpair faces;
    gmsh::model::getEntities(faces, 2);
    for (const auto& [dim, tag] : faces) read_face(tag);
    if (m_.elements.empty()) throw InputError("the mesh has no triangles or quadrangles on the model's surfaces");
    for (int n : foreign_) m_.free_face[n] = -1;
    return std::move(out_);
  }

 private:
  // The mesh node of node tag `tag` at xyz, added the first time it is seen.
  int node_index(std::size_t tag, const double* xyz) {
    const auto [it, inserted] = index_of_.emplace(tag, static_cast<int>(m_.x.size()));
    if (inserted) {
      out_.node_tags.push_back(tag);
      m_.x.emplace_back(xyz[0], xyz[1], xyz[2]);
      m_.u.emplace_back(0.0, 0.0);
      m_.free_face.push_back(-1);
    }
    return it->second;
  }

  void read_face(int tag) {
    const FaceElements elements =
        face_elements(tag, {2, 3}, "only linear triangles (2) and quadrangles (3) are supported");
    if (elements.count == 0) return;
    const int f = static_cast<int>(out_.faces.size());
    out_.faces.push_back(std::make_unique<GmshFace>(tag));
    m_.faces.push_back(out_.faces.back().get());
    // All nodes of the face with parametric coordinates on it (boundary nodes
    // reparametrized by Gmsh), and which of them are inside the face.
    std::vector<std::size_t> tags, inner_tags;
    std::vector<double> xyz, uv, inner_xyz, inner_uv;
    gmsh::model::mesh::getNodes(tags, xyz, uv, 2, tag, true, true);
    gmsh::model::mesh::getNodes(inner_tags, inner_xyz, inner_uv, 2, tag, false, true);
    if (!inner_tags.empty() && inner_uv.size() != 2 * inner_tags.size())
      throw InputError(cat("the mesh has no parametric coordinates for the nodes inside surface ", tag,
                           " (save it with Mesh.SaveParametric = 1)"));
    FaceNodes nodes;
    for (std::size_t i = 0; i < tags.size(); ++i) nodes.xyz_of[tags[i]] = &xyz[3 * i];
    if (uv.size() == 2 * tags.size())
      for (std::size_t i = 0; i < tags.size(); ++i) nodes.uv_of[tags[i]] = Eigen::Vector2d(uv[2 * i], uv[2 * i + 1]);
    const GmshFace& face = *out_.faces.back();
    for (std::size_t i = 0; i < inner_tags.size(); ++i) {
      const int n = node_index(inner_tags[i], &inner_xyz[3 * i]);
      m_.free_face[n] = f;
      m_.u[n] = Eigen::Vector2d(inner_uv[2 * i], inner_uv[2 * i + 1]);
      nodes.uv_of[inner_tags[i]] = m_.u[n];
      check_inner_node(face, tag, inner_tags[i], n);
    }
    const std::size_t first_element = m_.elements.size();
    add_elements(elements, f, tag, nodes);
    orient_like_the_normal(m_, face, first_element);
  }

  // Where a face's nodes are: coordinates (into Gmsh's arrays) and parametric
  // coordinates on the face, by node tag.
  struct FaceNodes {
    std::unordered_map<std::size_t, const double*> xyz_of;
    std::unordered_map<std::size_t, Eigen::Vector2d> uv_of;
  };

  // The checks of validate_surface_mesh on a node inside face `tag`, named with Gmsh tags.
  void check_inner_node(const GmshFace& face, int tag, std::size_t node_tag, int n) const {
    const std::string where =
        cat("node ", node_tag, " of surface ", tag, " at (u, v) = (", m_.u[n].x(), ", ", m_.u[n].y(), ")");
    const SurfacePoint p = face.evaluate(m_.u[n], 1);
    if (unit_normal(p).isZero())
      throw InputError(cat(where, " lies at a degenerate point of the surface (phi_u x phi_v = 0)"));
    if (!face.contains(m_.u[n]))
      throw InputError(cat(where, " is outside the surface's parameter range [", face.lower().x(), ", ",
                           face.upper().x(), "] x [", face.lower().y(), ", ", face.upper().y(), "]"));
    if (!face.contains_exactly(m_.u[n]))
      throw InputError(cat(where, " lies outside the trimmed face (in a trimmed-away part of its parameter range)"));
    const double scale = std::max(1.0, p.x.norm());
    if (!((p.x - m_.x[n]).norm() <= 1e-6 * scale))
      throw InputError(cat(where, ": the surface at these parametric coordinates is ", (p.x - m_.x[n]).norm(),
                           " away from the node"));
  }

  // The elements of face `tag` (mesh face f), each corner with its parametric
  // coordinates on the face.
  void add_elements(const FaceElements& elements, int f, int tag, FaceNodes& nodes) {
    for (std::size_t k = 0; k < elements.types.size(); ++k) {
      const int nv = elements.types[k] == 2 ? 3 : 4;
      for (std::size_t e = 0; e < elements.tags[k].size(); ++e) {
        SurfaceElement el;
        el.nv = nv;
        el.face = f;
        for (int i = 0; i < nv; ++i) {
          const std::size_t nt = elements.nodes[k][nv * e + i];
          const auto xt = nodes.xyz_of.find(nt);
          if (xt != nodes.xyz_of.end()) {
            el.v[i] = node_index(nt, xt->second);
          } else {
            // A node classified on another entity (a remeshed element across a
            // smooth junction between faces): fixed, with its parametric
            // coordinates on this face from the closest point.
            auto index = [this](std::size_t t, const double* x) { return node_index(t, x); };
            el.v[i] = foreign_node(nt, tag, index, nodes.uv_of);
            foreign_.push_back(el.v[i]);
          }
          const auto it = nodes.uv_of.find(nt);
          if (it == nodes.uv_of.end())
            throw InputError(cat("node ", nt, " of surface ", tag, " has no parametric coordinates on it"));
          m_.corner_uv.push_back(it->second);
        }
        for (int i = nv; i < 4; ++i) m_.corner_uv.push_back(Eigen::Vector2d::Zero());
        m_.elements.push_back(el);
        out_.face_tags.push_back(tag);
      }
    }
  }

  GmshSurfaceMesh out_;
  SurfaceMesh& m_ = out_.mesh;
  std::unordered_map<std::size_t, int> index_of_;  // node tag -> mesh node
  std::vector<int> foreign_;  // nodes used by elements of a face they are not on
};

}  // namespace

GmshSurfaceMesh read_surface_mesh() { return SurfaceMeshReader().read(); }

void write_mesh(const std::string& path, const GmshSurfaceMesh& m) {
  for (std::size_t i = 0; i < m.mesh.x.size(); ++i) {
    if (m.mesh.free_face[i] < 0) continue;
    const Eigen::Vector3d& x = m.mesh.x[i];
    const Eigen::Vector2d& u = m.mesh.u[i];
    gmsh::model::mesh::setNode(m.node_tags[i], {x.x(), x.y(), x.z()}, {u.x(), u.y()});
  }
  write_current_mesh(path);
}

void write_current_mesh(const std::string& path) {
  gmsh::option::setNumber("Mesh.SaveParametric", 1);
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  const fs::path target(path);
  // Gmsh picks the format from the extension: the temporary name ends in .msh.
  const fs::path tmp =
      target.parent_path() / cat(".", target.filename().string(), ".tmp", static_cast<long>(::getpid()), ".msh");
  try {
    gmsh::write(tmp.string());
  } catch (...) {
    const std::string why = gmsh_error();
    std::error_code ec;
    fs::remove(tmp, ec);
    throw IoError(cat("cannot write '", path, "': ", why));
  }
  std::error_code ec;
  if (!fs::exists(tmp, ec)) throw IoError(cat("cannot write '", path, "'"));
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw IoError(cat("cannot write '", path, "': ", ec.message()));
  }
}

}  // namespace meshopt::gmsh_io
