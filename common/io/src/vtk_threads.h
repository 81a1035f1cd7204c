#pragma once
// Private to toolkit_io: VTK's process-wide registries made once, before any
// thread uses VTK (the .vtu files are written on two lanes at once).
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>

namespace toolkit::io::detail {

/// VTK makes its object-factory registry (and its output window) on first use
/// without a lock: two threads making their first VTK objects at once can both
/// make a registry, and one leaks (LeakSanitizer caught it: 80 bytes from
/// vtkObjectFactoryCollection::New, in a run whose two output lanes started
/// together). Every entry point of the module calls this first: a
/// function-local static is made once, and other threads wait for it.
inline void prepare_vtk_for_threads() {
  static const bool ready = [] {
    vtkObjectFactory::GetRegisteredFactories();
    vtkOutputWindow::GetInstance();
    return true;
  }();
  (void)ready;
}

}  // namespace toolkit::io::detail
