#pragma once
// Gmsh's module loaded ahead (gmsh_module.cpp): a run that will make a quad
// layout loads it on a thread of its own while it reads and cleans its input,
// instead of when the layout's first mesh is made (0.14 s of the dynamic
// linker's work, on the core that the start of a run leaves idle).
#include <future>

namespace tspline_app {

class GmshPreload {
 public:
  GmshPreload();
  /// Waits for the load, if it is still going on: a module's libraries are
  /// not left half loaded while the program ends.
  ~GmshPreload();
  GmshPreload(const GmshPreload&) = delete;
  GmshPreload& operator=(const GmshPreload&) = delete;

 private:
  std::future<void> loading_;
};

}  // namespace tspline_app
