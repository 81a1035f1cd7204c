// Benchmark of libmeshopt on surfaces: node visits per second of the
// Gauss-Seidel sweeps of smooth_surface on a torus patch with analytic phi, for a
// structured triangle mesh of N x N nodes whose interior nodes are randomly
// displaced in parametric space (about 10% of them start tangled).
// Prints one table row:
//   nodes elements tangled_before sweeps seconds_per_sweep node_visits_per_s tangled_after min_q
// Usage: bench_surface N [SWEEPS]   (default 20 sweeps)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>

#include "meshopt/surface_smoother.h"
#include "toolkit/timing.h"

namespace {

/// Torus patch ((R + r cos v) cos u, (R + r cos v) sin u, r sin v), u in [0, pi], v in [0, 2].
class TorusPatch final : public meshopt::ParametricSurface {
 public:
  Eigen::Vector3d value(const Eigen::Vector2d& p) const override {
    const double w = R + r * std::cos(p.y());
    return {w * std::cos(p.x()), w * std::sin(p.x()), r * std::sin(p.y())};
  }
  meshopt::SurfacePoint evaluate(const Eigen::Vector2d& p, int) const override {
    const double cu = std::cos(p.x()), su = std::sin(p.x()), cv = std::cos(p.y()), sv = std::sin(p.y());
    const double w = R + r * cv;
    meshopt::SurfacePoint s;
    s.x = {w * cu, w * su, r * sv};
    s.d.col(0) = Eigen::Vector3d(-w * su, w * cu, 0.0);
    s.d.col(1) = Eigen::Vector3d(-r * sv * cu, -r * sv * su, r * cv);
    s.duu = {-w * cu, -w * su, 0.0};
    s.duv = {r * sv * su, -r * sv * cu, 0.0};
    s.dvv = {-r * cv * cu, -r * cv * su, -r * sv};
    return s;
  }
  bool contains(const Eigen::Vector2d& p) const override {
    return p.x() >= 0.0 && p.x() <= std::numbers::pi && p.y() >= 0.0 && p.y() <= 2.0;
  }

 private:
  double R = 2.0, r = 0.8;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_surface N [SWEEPS]\n");
    return 1;
  }
  const int n = std::atoi(argv[1]);
  const int sweeps = argc > 2 ? std::atoi(argv[2]) : 20;
  if (n < 3 || sweeps < 1) {
    std::fprintf(stderr, "bench_surface: N >= 3 and SWEEPS >= 1\n");
    return 1;
  }
  const TorusPatch torus;
  meshopt::SurfaceMesh m;
  m.faces = {&torus};
  const double du = std::numbers::pi / (n - 1), dv = 2.0 / (n - 1);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> U(-0.6, 0.6);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const bool fixed = i == 0 || j == 0 || i == n - 1 || j == n - 1;
      Eigen::Vector2d p(i * du, j * dv);
      if (!fixed) p += Eigen::Vector2d(U(rng) * du, U(rng) * dv);
      m.u.push_back(p);
      m.x.push_back(torus.value(p));
      m.free_face.push_back(fixed ? -1 : 0);
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      m.elements.push_back({{a, b, c, 0}, 3, 0});
      m.elements.push_back({{a, c, d, 0}, 3, 0});
    }
  meshopt::SurfaceSmoothingOptions opt;
  opt.max_sweeps = sweeps;
  opt.tol_x = opt.tol_f = 0.0;  // time exactly `sweeps` sweeps
  const auto before = meshopt::surface_mesh_quality(m, meshopt::SurfaceMeasure::shape);
  const auto t0 = std::chrono::steady_clock::now();
  const auto rep = meshopt::smooth_surface(m, opt);
  const double s = toolkit::seconds_since(t0);
  const auto after = meshopt::surface_mesh_quality(m, meshopt::SurfaceMeasure::shape);
  std::printf("%8zu %9zu %8zu %6d %12.4f %14.0f %8zu %6.3f\n", m.x.size(), m.elements.size(), before.tangled,
              rep.sweeps, s / rep.sweeps, static_cast<double>(rep.node_visits) / s, after.tangled, after.min);
  return 0;
}
