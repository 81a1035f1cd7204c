#include "tspline/detail/tmesh_submesh.h"
#include "tspline/tmesh/smoothing_problem.h"

#include <algorithm>

#include "meshopt/triangle_measure.h"

namespace tspline::detail {

namespace {

// Appends the triangles (v, p, q) for the pairs of `corners` (excluding v itself)
// that are not collinear with v, counter-clockwise in the parametric domain.
void append_cell_triangles(const TMesh& mesh, int v, const std::array<int, 4>& corners, double weight,
                           std::vector<meshopt::LocalTriangle>& out) {
  int other[4];
  int n = 0;
  for (int c : corners)
    if (c != v) other[n++] = c;
  const IPoint& pv = mesh.vertex_ipos(v);
  const Eigen::Vector2d uv = mesh.vertex_param(v);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      int a = other[i], b = other[j];
      const std::int64_t o = orient_exact(pv, mesh.vertex_ipos(a), mesh.vertex_ipos(b));
      if (o == 0) continue;  // the T-junction's own edge: flat in the ideal configuration
      if (o < 0) std::swap(a, b);
      meshopt::LocalTriangle t;
      t.a = a;
      t.b = b;
      t.ideal_inv = meshopt::ideal_inverse(uv, mesh.vertex_param(a), mesh.vertex_param(b));
      t.weight = weight;
      out.push_back(t);
    }
  }
}

}  // namespace

std::vector<meshopt::LocalTriangle> local_submesh(const TMesh& mesh, int v, bool weighted) {
  std::array<int, 4> around = mesh.cells_around(v);
  // Distinct cells (a T-junction cell appears in two quadrants).
  std::array<int, 4> cells{};
  int nc = 0;
  for (int c : around)
    if (c >= 0 && std::find(cells.begin(), cells.begin() + nc, c) == cells.begin() + nc) cells[nc++] = c;
  const int hanging_cell = mesh.vertex_hanging_cell(v);
  double min_size = 1.0;
  for (int k = 0; k < nc; ++k) min_size = std::min(min_size, mesh.cell_size(cells[k]));

  std::vector<meshopt::LocalTriangle> out;
  out.reserve(12);
  for (int k = 0; k < nc; ++k) {
    const int c = cells[k];
    double w = 1.0;
    if (weighted) {
      if (hanging_cell >= 0)
        w = (c == hanging_cell) ? 8.0 / 5.0 : 1.0;  // Eq. 5 and Appendix (hanging node case)
      else
        w = mesh.cell_size(c) / min_size;  // Eq. 4: scale factor 1, 2 or 4
    }
    append_cell_triangles(mesh, v, mesh.cell_corners(c), w, out);
  }
  return out;
}


}  // namespace tspline::detail

namespace tspline {

meshopt::SmoothingProblem build_smoothing_problem(const TMesh& mesh, bool weighted) {
  meshopt::SmoothingProblem problem;
  problem.nodes.reserve(mesh.num_vertices());
  problem.offsets.reserve(mesh.num_vertices() + 1);
  problem.triangles.reserve(mesh.num_vertices() * 12);
  for (int v = 0; v < static_cast<int>(mesh.num_vertices()); ++v) {
    if (mesh.vertex_on_boundary(v)) continue;
    const std::vector<meshopt::LocalTriangle> tris = detail::local_submesh(mesh, v, weighted);
    problem.add_node(v, tris);
  }
  return problem;
}

}  // namespace tspline
