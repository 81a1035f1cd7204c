// Benchmark of `meshopt smooth` on a CAD model: a torus (R 2, r 0.6)
// fused with a pipe (a cylinder of radius 0.3 through its tube), OpenCASCADE,
// meshed by Gmsh, then every STRIDE-th node inside a face moved by a random
// parametric offset (a fifth of the triangles tangled for the defaults), then
// smooth_surface as the command runs it. Writes model.brep and tangled.msh in
// DIR (if given) so that `meshopt smooth DIR/model.brep --mesh DIR/tangled.msh`
// reproduces the run. Prints one row:
//   triangles free_nodes tangled_before sweeps node_visits seconds visits_per_s tangled_after min_q
// Usage: bench_smooth_cad [SIZE [STRIDE [DIR]]]   (defaults 0.12, 2)
#include <gmsh.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cad_fixtures.h"
#include "meshopt/gmsh/gmsh_mesh.h"
#include "meshopt/surface_smoother.h"
#include "toolkit/timing.h"


int main(int argc, char** argv) {
  const double size = argc > 1 ? std::atof(argv[1]) : 0.12;
  const int stride = argc > 2 ? std::atoi(argv[2]) : 2;
  const std::string dir = argc > 3 ? argv[3] : "";
  if (!(size > 0.0) || stride < 1) {
    std::fprintf(stderr, "usage: bench_smooth_cad [SIZE [STRIDE [DIR]]]\n");
    return 1;
  }
  meshopt::gmsh_io::Session session;
  cad_fixtures::add_torus_pipe();
  if (!dir.empty()) {
    gmsh::write(dir + "/model.brep");
    gmsh::clear();
    meshopt::gmsh_io::open_model(dir + "/model.brep");
  }
  gmsh::option::setNumber("Mesh.MeshSizeMax", size);
  meshopt::gmsh_io::generate_surface_mesh();
  cad_fixtures::tangle(stride, 0.03, 7);
  if (!dir.empty()) {
    gmsh::option::setNumber("Mesh.SaveParametric", 1);
    gmsh::write(dir + "/tangled.msh");
  }
  meshopt::gmsh_io::GmshSurfaceMesh g = meshopt::gmsh_io::read_surface_mesh();
  std::size_t free_nodes = 0;
  for (int f : g.mesh.free_face) free_nodes += f >= 0;
  meshopt::SurfaceSmoothingOptions opt;
  const auto t0 = std::chrono::steady_clock::now();
  const meshopt::SurfaceSmoothingReport rep = meshopt::smooth_surface(g.mesh, opt);
  const double s = toolkit::seconds_since(t0);
  const meshopt::ElementQualities after = meshopt::surface_mesh_quality(g.mesh, meshopt::SurfaceMeasure::shape);
  std::printf("%9zu %10zu %8zu %6d %11zu %8.3f %12.0f %8zu %6.3f\n", g.mesh.elements.size(), free_nodes,
              rep.tangled_before, rep.sweeps, rep.node_visits, s, static_cast<double>(rep.node_visits) / s,
              rep.tangled_after, after.min);
  return 0;
}
