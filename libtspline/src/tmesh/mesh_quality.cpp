#include "tspline/tmesh/mesh_quality.h"

#include <algorithm>

#include <Eigen/LU>

#include "meshopt/triangle_measure.h"

namespace tspline {

std::vector<std::array<int, 3>> cell_triangles(const TMesh& mesh, int c) {
  const std::array<int, 4>& k = mesh.cell_corners(c);
  std::vector<std::array<int, 3>> tris = {{k[0], k[1], k[3]}, {k[1], k[2], k[0]}, {k[2], k[3], k[1]},
                                          {k[3], k[0], k[2]}};
  for (int h : mesh.cell_edge_midpoints(c)) {
    if (h < 0) continue;
    const IPoint& ph = mesh.vertex_ipos(h);
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        const std::int64_t o = orient_exact(ph, mesh.vertex_ipos(k[i]), mesh.vertex_ipos(k[j]));
        if (o > 0) tris.push_back({h, k[i], k[j]});
        if (o < 0) tris.push_back({h, k[j], k[i]});
      }
    }
  }
  return tris;
}

namespace {

template <class Visit>
void for_each_triangle_quality(const TMesh& mesh, int c, const std::vector<Eigen::Vector2d>& x, Visit visit) {
  for (const auto& t : cell_triangles(mesh, c)) {
    const Eigen::Matrix2d winv =
        meshopt::ideal_inverse(mesh.vertex_param(t[0]), mesh.vertex_param(t[1]), mesh.vertex_param(t[2]));
    const Eigen::Matrix2d S = meshopt::weighted_jacobian(x[t[0]], x[t[1]], x[t[2]], winv);
    visit(S.determinant(), meshopt::mean_ratio(S));
  }
}

}  // namespace

std::vector<CellQuality> cell_qualities(const TMesh& mesh, const std::vector<Eigen::Vector2d>& x) {
  std::vector<CellQuality> out(mesh.num_cells());
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    CellQuality& q = out[c];
    for_each_triangle_quality(mesh, c, x, [&](double sigma, double quality) {
      if (!(sigma > 0.0)) q.valid = false;
      q.min_mean_ratio = std::min(q.min_mean_ratio, quality);
    });
  }
  return out;
}

MeshQualityStats mesh_quality(const TMesh& mesh, const std::vector<Eigen::Vector2d>& x) {
  MeshQualityStats s;
  s.cells = mesh.num_cells();
  double sum = 0.0;
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    bool valid = true;
    for_each_triangle_quality(mesh, c, x, [&](double sigma, double quality) {
      ++s.triangles;
      if (!(sigma > 0.0)) valid = false, ++s.inverted_triangles;
      s.min_mean_ratio = std::min(s.min_mean_ratio, quality);
      sum += quality;
    });
    if (!valid) ++s.inverted_cells;
  }
  s.mean_mean_ratio = s.triangles ? sum / static_cast<double>(s.triangles) : 0.0;
  return s;
}

}  // namespace tspline
