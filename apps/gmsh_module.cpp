// The tspline program's quad mesher: Gmsh's (libtspline's
// src/layout/quad_mesher_gmsh.cpp), built as the module libtspline_gmsh.so
// and loaded at the first quad layout. Linked before libtspline, this
// quad_mesher_backend() takes the place of the one linked into the libraries,
// so the program does not load Gmsh and the ninety libraries it needs at
// every start (0.24 s of each run: `tspline --help` 0.33 -> 0.07 s). The
// module is looked for in TSPLINE_GMSH_MODULE (a path), next to the program
// (the build tree), and where `cmake --install` puts it.
#include "module_loader.h"
#include "tspline/detail/quad_mesher_backend.h"
#include "tspline/errors.h"

#ifndef TSPLINE_MODULE_FROM_BINDIR
#define TSPLINE_MODULE_FROM_BINDIR "../lib/tspline"
#endif

namespace tspline::detail {

const QuadMesherBackend& quad_mesher_backend() {
  // Loaded once (thread-safe); a failure is thrown again at every call.
  static const QuadMesherBackend* const backend = tspline_app::load_module<QuadMesherBackend>(
      {"libtspline_gmsh.so", "TSPLINE_GMSH_MODULE", "tspline_quad_mesher_backend", "a quad layout",
       "Gmsh module", TSPLINE_MODULE_FROM_BINDIR});
  return *backend;
}

}  // namespace tspline::detail
