#pragma once
// Internal to libtspline and the tspline program, not part of the public
// interface. The quad mesher's Gmsh part (layout/quad_mesher_gmsh.cpp) as a
// table of functions: in the libraries it is linked in (quad_mesher_gmsh.cpp
// defines quad_mesher_backend()); the tspline program defines
// quad_mesher_backend() itself and loads quad_mesher_gmsh.cpp, built as the
// module libtspline_gmsh.so, at its first quad layout (apps/gmsh_module.cpp),
// so that a run that makes no layout does not load Gmsh and the ninety
// libraries it needs (0.24 s of every start: `tspline --help` 0.33 -> 0.07 s).
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "tspline/layout/quad_mesher.h"

namespace tspline::detail {

struct QuadMesherBackend {
  /// quad_mesh's mesh, made by Gmsh in the calling process.
  PlanarQuadMesh (*mesh)(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                         const std::function<double(const Eigen::Vector2d&)>& size);
};

/// The Gmsh mesher. \throw IoError where the program's module cannot be loaded.
const QuadMesherBackend& quad_mesher_backend();

}  // namespace tspline::detail

/// The module's entry: its mesher (quad_mesher_gmsh.cpp).
extern "C" const tspline::detail::QuadMesherBackend* tspline_quad_mesher_backend();
