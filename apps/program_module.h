#pragma once
// The tspline program's modules: parts of the libraries built alone as shared
// modules (libtspline_gis.so: GDAL; libtspline_gmsh.so: Gmsh) that the program
// loads only when a run needs them, so that it does not load those libraries
// and the hundreds they need at every start. A module is looked for at the
// path in its environment variable, next to the program (the build tree), and
// where `cmake --install` puts it (<libdir>/tspline).
namespace tspline_app {

struct ProgramModule {
  const char* file;        ///< "libtspline_gis.so"
  const char* variable;    ///< the environment variable with its path: "TSPLINE_GIS_MODULE"
  const char* entry;       ///< the extern "C" function to find in it
  const char* needed_for;  ///< what needs it, for messages: "GIS input"
  const char* library;     ///< what it holds, for messages: "GDAL"
};

/// The module's entry function, the module loaded and kept loaded (its
/// libraries may keep state, as GDAL its drivers). \throw tspline::IoError
/// naming the module, where it was looked for and the variable.
void* load_program_module(const ProgramModule& module);

}  // namespace tspline_app
