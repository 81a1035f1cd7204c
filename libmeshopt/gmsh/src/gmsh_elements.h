#pragma once
// Helper of the Gmsh adapter (internal): the mesh elements of a model surface,
// checked to be of the element types the caller handles.
#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

namespace meshopt::gmsh_io {

/// The elements of one surface as gmsh::model::mesh::getElements gives them:
/// per element type, the element tags and their nodes (all nodes of an element
/// in a row).
struct FaceElements {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> tags, nodes;
  std::size_t count = 0;  ///< elements of all types
};

/// The elements of surface `tag` of the current model. \throw InputError if
/// one has a Gmsh element type not in `allowed`; the message ends with
/// `supported` (what the caller can handle).
FaceElements face_elements(int tag, std::initializer_list<int> allowed, const std::string& supported);

}  // namespace meshopt::gmsh_io
