// Benchmark of `meshopt remesh`: the fused torus and pipe of
// bench_smooth_cad (OpenCASCADE, several faces, sharp intersection curves)
// meshed by Gmsh at size 4 L, then remeshed (Dassi et al. 2014, K = 3, I = J = 4)
// with target 6D length L and anisotropy S. Prints one row:
//   L s triangles_in triangles_out seconds_sampling seconds_optimizing triangles_per_s peak_MiB
// Usage: bench_remesh [L [S]]   (defaults 0.05, 0.25)
#include <gmsh.h>
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <vector>

#include "cad_fixtures.h"
#include "meshopt/gmsh/gmsh_mesh.h"
#include "meshopt/gmsh/gmsh_remesh_model.h"
#include "meshopt/remesh.h"

int main(int argc, char** argv) {
  const double length = argc > 1 ? std::atof(argv[1]) : 0.05;
  const double s = argc > 2 ? std::atof(argv[2]) : 0.25;
  if (!(length > 0.0) || !(s >= 0.0)) {
    std::fprintf(stderr, "usage: bench_remesh [L [S]]\n");
    return 1;
  }
  meshopt::gmsh_io::Session session;
  cad_fixtures::add_torus_pipe();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 4.0 * length);
  meshopt::gmsh_io::generate_surface_mesh();
  const meshopt::gmsh_io::GmshRemeshGeometry g(meshopt::gmsh_io::detect_features(30.0 * std::numbers::pi / 180.0));
  meshopt::RemeshMesh m = meshopt::gmsh_io::read_remesh_mesh(g);
  const std::size_t before = m.live_triangles();
  meshopt::RemeshOptions opt;
  opt.length = length;
  opt.anisotropy = s;
  const meshopt::RemeshReport rep = meshopt::remesh(m, g, opt);
  const double seconds = rep.seconds_sampling + rep.seconds_optimizing;
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%8.4f %6.3f %10zu %10zu %9.2f %9.2f %10.0f %8.1f\n", length, s, before, m.live_triangles(),
              rep.seconds_sampling, rep.seconds_optimizing, static_cast<double>(m.live_triangles()) / seconds,
              static_cast<double>(ru.ru_maxrss) / 1024.0);
  return 0;
}
