#pragma once
// Internal to libtspline and the tspline program, not part of the public
// interface. The Gmsh part of quad_mesh (layout/quad_mesher.h), the mesh made
// in this process, as a function: in the libraries it is linked in
// (layout/quad_mesher_gmsh.cpp defines gmsh_backend()); the tspline program
// defines gmsh_backend() itself and loads quad_mesher_gmsh.cpp, built as the
// module libtspline_gmsh.so (apps/gmsh_module.cpp), so that a run that makes
// no quad layout does not load Gmsh and the 64 libraries it needs (OpenCASCADE,
// FLTK, OpenGL, ...): 0.14 s at every start of the program.
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "tspline/layout/quad_mesher.h"

namespace tspline::detail {

struct GmshBackend {
  /// quad_mesh's mesh, made by Gmsh in the calling process.
  PlanarQuadMesh (*quad_mesh)(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                              const std::function<double(const Eigen::Vector2d&)>& size);
};

/// The quad mesher's Gmsh. \throw IoError where the program's module cannot be loaded.
const GmshBackend& gmsh_backend();

}  // namespace tspline::detail

/// The module's entry: its quad mesher (quad_mesher_gmsh.cpp).
extern "C" const tspline::detail::GmshBackend* tspline_gmsh_backend();
