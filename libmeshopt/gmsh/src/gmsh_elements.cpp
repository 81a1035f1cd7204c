#include "gmsh_elements.h"

#include <gmsh.h>

#include <algorithm>

#include "gmsh_util.h"
#include "toolkit/errors.h"

namespace meshopt::gmsh_io {

FaceElements face_elements(int tag, std::initializer_list<int> allowed, const std::string& supported) {
  FaceElements out;
  gmsh::model::mesh::getElements(out.types, out.tags, out.nodes, 2, tag);
  for (std::size_t k = 0; k < out.types.size(); ++k) {
    if (std::find(allowed.begin(), allowed.end(), out.types[k]) == allowed.end())
      throw toolkit::InputError(cat("surface ", tag, " has elements of Gmsh type ", out.types[k], "; ", supported));
    out.count += out.tags[k].size();
  }
  return out;
}

}  // namespace meshopt::gmsh_io
