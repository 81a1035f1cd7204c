#pragma once
// Reading and writing surface meshes of CAD models through the Gmsh API: the
// model (STEP, IGES, BRep, .geo) gives the faces; a .msh file (or Gmsh's own 2D
// mesher) gives the triangles/quads with the parametric coordinates of the nodes
// inside faces. Nodes on CAD curves and points are fixed (free_face = -1).
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "meshopt/gmsh/gmsh_face.h"
#include "meshopt/surface_mesh.h"
#include "toolkit/errors.h"

namespace meshopt::gmsh_io {

// Errors: toolkit::InputError for bad input (unreadable model, mesh without
// parametric coordinates, unsupported elements...), toolkit::IoError for a file
// that cannot be written (toolkit/errors.h).
using toolkit::InputError;  // the toolkit's own classes (no copies), by their short names here
using toolkit::IoError;

/// gmsh::initialize / finalize for the lifetime of the object (terminal output off
/// unless `verbose`). One at a time per process.
class Session {
 public:
  explicit Session(bool verbose = false);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

/// Opens a CAD model (replacing the current one). \throw InputError naming the file.
void open_model(const std::string& path);

/// Merges a .msh mesh of the current model. \throw InputError naming the file.
void merge_mesh(const std::string& path);

/// Meshes the model's surfaces with Gmsh (2D). \throw InputError if that fails.
void generate_surface_mesh();

/// The model's surface mesh in libmeshopt form, with the Gmsh tags to write it back.
struct GmshSurfaceMesh {
  std::vector<std::unique_ptr<GmshFace>> faces;  ///< mesh.faces point into these
  SurfaceMesh mesh;
  std::vector<std::size_t> node_tags;  ///< Gmsh node tag of each mesh node
  std::vector<int> face_tags;          ///< Gmsh surface tag of each element's face
};

/// Reads the linear triangles and quads of every surface of the current model.
/// \throw InputError for other element types, a face without elements is skipped;
/// nodes inside a face without parametric coordinates, outside the face's
/// parameter range, or at a degenerate point of the face are reported by name.
GmshSurfaceMesh read_surface_mesh();

/// Stores the positions and parametric coordinates of the free nodes in the Gmsh
/// model and writes it as MSH 4.1 with parametric coordinates, atomically
/// (temporary file next to `path`, then rename). \throw IoError.
void write_mesh(const std::string& path, const GmshSurfaceMesh& m);

/// Writes the current model's mesh as MSH 4.1 with parametric coordinates,
/// atomically (temporary file next to `path`, then rename). \throw IoError.
void write_current_mesh(const std::string& path);

}  // namespace meshopt::gmsh_io
