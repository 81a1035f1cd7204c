// tspline.meshopt: libmeshopt on Gmsh models (smooth, remesh), where the
// build has Gmsh (meshopt_gmsh); without it the submodule says so.
#include "bindings.h"

namespace tspline_python {

void bind_meshopt(py::module_& m) {
  py::module_ sub = m.def_submodule("meshopt", "Mesh optimization on CAD models (libmeshopt through Gmsh)");
  sub.attr("available") = false;
}

}  // namespace tspline_python
