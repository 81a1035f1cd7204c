// Example 5: untangle and smooth a planar triangle mesh with libmeshopt.
//
//   example_untangle
//
// libmeshopt knows nothing about T-splines: it moves free nodes so that every
// triangle becomes valid and as close as possible to an ideal shape. Each
// free node x has a local submesh of triangles (x, a, b); the objective is the
// sum of the regularized distortions |S|^2 / (2 h(sigma)), S = A W^{-1}
// (Brovka 2013 Eqs. 1-3; Gargallo-Peiro Sect. 4), which is finite and smooth
// even for inverted triangles (sigma < 0) while delta > 0, so untangling and
// smoothing happen in one minimization.
#include <cmath>
#include <cstdio>
#include <exception>
#include <random>
#include <vector>

#include "meshopt/node_smoother.h"
#include "meshopt/triangle_measure.h"

int run(int, char**) {
  // A structured triangle mesh of the unit square: (n+1)^2 nodes, 2 n^2 triangles.
  const int n = 12;
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  std::vector<Eigen::Vector2d> x;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) x.emplace_back(static_cast<double>(i) / n, static_cast<double>(j) / n);
  std::vector<std::array<int, 3>> tri;  // counter-clockwise
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      tri.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tri.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }

  // Tangle it: move every interior node randomly by up to 1.5 cell widths.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-1.5 / n, 1.5 / n);
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) x[id(i, j)] += Eigen::Vector2d(jitter(rng), jitter(rng));

  // The ideal triangle: equilateral (W^{-1} is the same for every triangle).
  const Eigen::Matrix2d ideal = meshopt::ideal_inverse({0, 0}, {1, 0}, {0.5, std::sqrt(3.0) / 2});
  auto quality = [&](const std::array<int, 3>& t) {
    return meshopt::mean_ratio(meshopt::weighted_jacobian(x[t[0]], x[t[1]], x[t[2]], ideal));
  };
  auto summary = [&](const char* when) {
    int inverted = 0;
    double qmin = 1.0;
    for (const auto& t : tri) {
      const double q = quality(t);
      inverted += q <= 0.0;
      qmin = std::min(qmin, q);
    }
    std::printf("%s: inverted %d of %zu, min quality %.4f\n", when, inverted, tri.size(), qmin);
    return inverted;
  };
  summary("before");

  // The problem: each interior node with its triangles, rotated so that the
  // free node comes first: (x, a, b) counter-clockwise.
  meshopt::SmoothingProblem problem;
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) {
      const int v = id(i, j);
      std::vector<meshopt::LocalTriangle> local;
      for (const auto& t : tri)
        for (int k = 0; k < 3; ++k)
          if (t[k] == v) local.push_back({t[(k + 1) % 3], t[(k + 2) % 3], ideal, 1.0});
      problem.add_node(v, local);
    }
  const meshopt::SmoothingReport report = meshopt::smooth(x, problem);
  std::printf("sweeps %d, converged %d, tangled nodes %zu -> %zu\n", report.sweeps, report.converged ? 1 : 0,
              report.tangled_nodes_before, report.tangled_nodes_after);
  const int inverted = summary("after");
  return inverted == 0 && report.converged ? 0 : 1;
}
