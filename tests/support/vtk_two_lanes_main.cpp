// Test helper (test_io, "first use of VTK on two threads"): a new process whose
// first VTK objects are made by two threads at once, each writing a .vtu, as
// the output lanes of `tspline param` do. VTK makes its object-factory
// registry on first use without a lock; without toolkit_io's one-time set-up
// both threads can make one and one leaks, which LeakSanitizer reports at exit
// (a non-zero exit status) in the sanitizer build.
// Usage: vtk_two_lanes DIR (writes DIR/lane0.vtu and DIR/lane1.vtu)
#include <cstdio>
#include <exception>
#include <string>
#include <thread>

#include "toolkit/io/vtu_writer.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: vtk_two_lanes DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  std::exception_ptr failed[2];
  auto lane = [&](int k) {
    try {
      toolkit::io::VtuMesh m;
      m.points = {{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}};
      m.cells = {{0, 1, 2}};
      toolkit::io::write_vtu(dir + "/lane" + std::to_string(k) + ".vtu", m);
    } catch (...) {
      failed[k] = std::current_exception();
    }
  };
  std::thread a(lane, 0), b(lane, 1);
  a.join();
  b.join();
  for (const std::exception_ptr& e : failed)
    if (e) {
      try {
        std::rethrow_exception(e);
      } catch (const std::exception& x) {
        std::fprintf(stderr, "vtk_two_lanes: %s\n", x.what());
      }
      return 1;
    }
  return 0;
}
