// The tspline program's quad mesher: Gmsh (libtspline's
// src/layout/quad_mesher_gmsh.cpp), built as the module libtspline_gmsh.so
// and loaded for the first quad layout (program_module.h). Linked before
// libtspline, this gmsh_backend() takes the place of the one linked into the
// libraries, so the program does not load Gmsh and the 64 libraries it needs
// (OpenCASCADE, FLTK, OpenGL, ...) at every start: 0.14 s of each run.
#include "gmsh_module.h"

#include <future>

#include "program_module.h"
#include "tspline/detail/gmsh_backend.h"

namespace tspline::detail {

const GmshBackend& gmsh_backend() {
  // Loaded once (thread-safe); a failure is thrown again at every call.
  static const GmshBackend* const backend = [] {
    using Entry = const GmshBackend* (*)();
    return reinterpret_cast<Entry>(
        tspline_app::load_program_module({"libtspline_gmsh.so", "TSPLINE_GMSH_MODULE", "tspline_gmsh_backend",
                                          "an automatic quad layout", "Gmsh"}))();
  }();
  return *backend;
}

}  // namespace tspline::detail

namespace tspline_app {

GmshPreload::GmshPreload()
    : loading_(std::async(std::launch::async, [] {
        try {
          tspline::detail::gmsh_backend();
        } catch (...) {  // (said where the mesher is used, if it is)
        }
      })) {}

GmshPreload::~GmshPreload() = default;  // (the future waits for the load)

}  // namespace tspline_app
