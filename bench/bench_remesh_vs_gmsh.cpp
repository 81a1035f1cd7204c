// Triangles needed for a given chordal deviation: the remesher
// (Dassi et al. 2014) against Gmsh's isotropic meshes of the same CAD part, the
// fused torus and pipe of bench_smooth_cad (OpenCASCADE, 5 faces, sharp
// intersection curves). The deviation is the one `meshopt remesh` reports: the
// largest distance of a triangle centroid from the model. For Gmsh, the mesh
// size (uniform), and separately the number of elements per 2 pi radius of
// curvature (Mesh.MeshSizeFromCurvature), are bisected to the smallest mesh
// whose deviation does not exceed the remesher's. Prints
//   remesh: L s triangles deviation seconds
//   uniform: size triangles deviation
//   curvature: n triangles deviation
//   ratio remesh / best isotropic
// and, for the remesher's 8 worst triangles, their deviation (measured and
// estimated from the corner normals), 6D edge lengths / L and principal curvatures,
// and the histogram of 6D edge length / L.
// Usage: bench_remesh_vs_gmsh [L [S [D [cylinder_sphere]]]]   (defaults 0.2, 1,
// 0: D is RemeshOptions::max_deviation, the remesher's estimated-deviation cap;
// cylinder_sphere: the fused cylinder r 0.5 and sphere r 0.8 of cad_fixtures)
#include <gmsh.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "cad_fixtures.h"
#include "meshopt/gmsh/gmsh_mesh.h"
#include "meshopt/gmsh/gmsh_remesh_model.h"
#include "meshopt/remesh.h"
#include "meshopt/remesh_statistics.h"
#include "toolkit/timing.h"

namespace {

struct Sample {
  double parameter = 0.0;
  std::size_t triangles = 0;
  double deviation = 0.0;
};

bool cylinder_sphere = false;  ///< the fused cylinder and sphere of cad_fixtures instead

void make_model() {
  gmsh::clear();
  if (cylinder_sphere)
    cad_fixtures::add_cylinder_sphere();
  else
    cad_fixtures::add_torus_pipe();
}

/// Where the remesher's deviation comes from: its worst triangles, and the 6D lengths.
void print_worst(const meshopt::RemeshMesh& m, const meshopt::gmsh_io::GmshRemeshGeometry& g, double length,
                 double s) {
  const auto c = meshopt::gmsh_io::project_centroids(m, g);
  const auto k = meshopt::gmsh_io::curvature_alignment(m, c);
  std::vector<int> order(m.triangles.size());
  for (std::size_t t = 0; t < order.size(); ++t) order[t] = static_cast<int>(t);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return c.distance[a] > c.distance[b]; });
  double max_estimate = 0.0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    max_estimate = std::max(max_estimate, meshopt::triangle_deviation(m, static_cast<int>(t)));
  std::printf("largest estimated deviation %.4g\n", max_estimate);
  for (std::size_t r = 0; r < 8 && r < order.size(); ++r) {
    const int t = order[r];
    const auto& v = m.triangles[t].v;
    std::printf("  worst %zu: deviation %.4g estimate %.4g 6D/L %.2f %.2f %.2f 3D %.3f %.3f %.3f kappa %.2f %.2f\n", r,
                c.distance[t], meshopt::triangle_deviation(m, t),
                meshopt::edge_length6d(m, v[0], v[1], s) / length, meshopt::edge_length6d(m, v[1], v[2], s) / length,
                meshopt::edge_length6d(m, v[2], v[0], s) / length, (m.vertices[v[0]].x - m.vertices[v[1]].x).norm(),
                (m.vertices[v[1]].x - m.vertices[v[2]].x).norm(), (m.vertices[v[2]].x - m.vertices[v[0]].x).norm(),
                k.kappa_low[t], k.kappa_high[t]);
  }
  const meshopt::RemeshStatistics st = meshopt::remesh_statistics(m, length, s);
  std::printf("6D length / L: min %.3f mean %.3f max %.3f; histogram from %.2f by %.2f:", st.length_ratio_min,
              st.length_ratio_mean, st.length_ratio_max, st.length_ratio.lo, st.length_ratio.width);
  for (auto n : st.length_ratio.counts) std::printf(" %zu", static_cast<std::size_t>(n));
  std::printf("\n");
}

double max_deviation(const meshopt::RemeshMesh& m, const meshopt::gmsh_io::GmshRemeshGeometry& g) {
  const auto c = meshopt::gmsh_io::project_centroids(m, g);
  return *std::max_element(c.distance.begin(), c.distance.end());
}

/// Meshes the model with Gmsh options set by `configure` and measures it.
Sample gmsh_mesh(const std::function<void()>& configure, double parameter) {
  make_model();
  configure();
  meshopt::gmsh_io::generate_surface_mesh();
  const meshopt::gmsh_io::GmshRemeshGeometry g(meshopt::gmsh_io::detect_features(std::numbers::pi / 6));
  const meshopt::RemeshMesh m = meshopt::gmsh_io::read_remesh_mesh(g);
  return {parameter, m.live_triangles(), max_deviation(m, g)};
}

/// Bisects `param` in [lo, hi] (deviation decreasing from lo to hi) for the
/// cheapest mesh with deviation <= target.
Sample bisect(double lo, double hi, double target, bool geometric, const std::function<Sample(double)>& mesh) {
  Sample best = mesh(hi);
  for (int it = 0; it < 8; ++it) {
    const double mid = geometric ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
    const Sample s = mesh(mid);
    if (s.deviation <= target) {
      hi = mid;
      if (s.triangles < best.triangles || best.deviation > target) best = s;
    } else {
      lo = mid;
    }
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const double length = argc > 1 ? std::atof(argv[1]) : 0.2;
  const double s = argc > 2 ? std::atof(argv[2]) : 1.0;
  const double cap = argc > 3 ? std::atof(argv[3]) : 0.0;
  cylinder_sphere = argc > 4 && std::string(argv[4]) == "cylinder_sphere";
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  meshopt::gmsh_io::Session session;
  make_model();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 2.0 * length);
  // A start that resolves the part's curvature (12 elements per 2 pi radius):
  // on a start coarser than the pipe's radius, curved feature edges cannot be
  // split without folding a triangle over its opposite corner.
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 12);
  meshopt::gmsh_io::generate_surface_mesh();
  const meshopt::gmsh_io::GmshRemeshGeometry g(meshopt::gmsh_io::detect_features(std::numbers::pi / 6));
  meshopt::RemeshMesh m = meshopt::gmsh_io::read_remesh_mesh(g);
  meshopt::RemeshOptions opt;
  opt.length = length;
  opt.anisotropy = s;
  opt.max_deviation = cap;
  const auto t0 = std::chrono::steady_clock::now();
  meshopt::remesh(m, g, opt);
  const double seconds = toolkit::seconds_since(t0);
  const double target = max_deviation(m, g);
  std::printf("remesh: L %g s %g D %g triangles %zu deviation %.4g seconds %.1f\n", length, s, cap, m.live_triangles(),
              target, seconds);
  print_worst(m, g, length, s);
  const Sample uniform = bisect(0.5, 0.02, target, true, [](double h) {
    return gmsh_mesh(
        [h] {
          gmsh::option::setNumber("Mesh.MeshSizeMax", h);
          gmsh::option::setNumber("Mesh.MeshSizeMin", h);
          gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
        },
        h);
  });
  std::printf("uniform: size %.4g triangles %zu deviation %.4g\n", uniform.parameter, uniform.triangles,
              uniform.deviation);
  const Sample curved = bisect(6.0, 150.0, target, true, [](double n) {
    return gmsh_mesh(
        [n] {
          gmsh::option::setNumber("Mesh.MeshSizeMin", 0.0);
          gmsh::option::setNumber("Mesh.MeshSizeMax", 1.0);
          gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", n);
        },
        n);
  });
  std::printf("curvature: n %.4g triangles %zu deviation %.4g\n", curved.parameter, curved.triangles,
              curved.deviation);
  const std::size_t best = std::min(uniform.triangles, curved.triangles);
  std::printf("ratio remesh / best isotropic: %.3f\n", static_cast<double>(m.live_triangles()) / best);
  return 0;
}
