#include "tspline/spline/tspline_fit.h"

#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <chrono>
#include <cmath>
#include <sstream>

#include "meshopt/node_smoother.h"
#include "meshopt/triangle_measure.h"
#include "toolkit/timing.h"
#include "tspline/errors.h"

namespace tspline {

namespace {

using Kind = BlendingFunction::Kind;

bool on_border(const Eigen::Vector2d& uv) {
  return uv.x() == 0.0 || uv.y() == 0.0 || uv.x() == 1.0 || uv.y() == 1.0;
}

// Physical position of a vertex of the T-mesh at the integer point p (it must exist).
Eigen::Vector2d vertex_at(const TMesh& mesh, const std::vector<Eigen::Vector2d>& x, const IPoint& p) {
  const int v = mesh.find_vertex(p);
  if (v < 0) throw NumericalError("interpolation: expected a T-mesh vertex at an edge end");
  return x[v];
}

IPoint to_ipoint(const Eigen::Vector2d& uv) {
  const double R = static_cast<double>(TMesh::kRoot);
  return {static_cast<std::int64_t>(uv.x() * R), static_cast<std::int64_t>(uv.y() * R)};
}

// Centre of a corner cell by a fictitious 2x2 split (Sect. 5.3): the four
// sub-cells' corners are the cell corners, the edge midpoints (on the polygon for
// border edges, the hanging vertex or the physical edge midpoint otherwise) and
// the free centre, placed by minimizing the regular 12-triangle objective.
Eigen::Vector2d corner_cell_centre(const TMesh& mesh, int c, const std::vector<Eigen::Vector2d>& x,
                                   const BoundaryMap& boundary) {
  const auto& k = mesh.cell_corners(c);
  const auto& mid = mesh.cell_edge_midpoints(c);
  const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c), m = 0.5 * (lo + hi);
  // Local nodes: 0..3 corners (CCW from lower-left), 4..7 edge midpoints (bottom,
  // right, top, left), 8 the centre.
  std::vector<Eigen::Vector2d> P(9), U(9);
  for (int i = 0; i < 4; ++i) P[i] = x[k[i]], U[i] = mesh.vertex_param(k[i]);
  const Eigen::Vector2d mid_uv[4] = {{m.x(), lo.y()}, {hi.x(), m.y()}, {m.x(), hi.y()}, {lo.x(), m.y()}};
  for (int e = 0; e < 4; ++e) {
    U[4 + e] = mid_uv[e];
    if (mid[e] >= 0)
      P[4 + e] = x[mid[e]];  // a hanging vertex already sits there
    else if (on_border(mid_uv[e]))
      P[4 + e] = boundary.point_at(mid_uv[e]);
    else
      P[4 + e] = 0.5 * (P[e] + P[(e + 1) % 4]);
  }
  U[8] = m;
  P[8] = 0.25 * (P[0] + P[1] + P[2] + P[3]);
  // Sub-cells around the centre (CCW corner lists) and their triangles at the centre.
  const int sub[4][4] = {{0, 4, 8, 7}, {4, 1, 5, 8}, {8, 5, 2, 6}, {7, 8, 6, 3}};
  std::vector<meshopt::LocalTriangle> tris;
  for (const auto& q : sub) {
    int other[3], n = 0;
    for (int i : q)
      if (i != 8) other[n++] = i;
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b) {
        int i = other[a], j = other[b];
        const Eigen::Vector2d ui = U[i] - U[8], uj = U[j] - U[8];
        const double o = ui.x() * uj.y() - ui.y() * uj.x();
        if (o == 0.0) continue;
        if (o < 0) std::swap(i, j);
        meshopt::LocalTriangle t;
        t.a = i, t.b = j, t.ideal_inv = meshopt::ideal_inverse(U[8], U[i], U[j]);
        tris.push_back(t);
      }
  }
  meshopt::SmoothingOptions opt;
  opt.newton_iterations_per_visit = 100;
  // Converge to round-off: an affine image of the square must give exactly the
  // image of the centre (then affine maps are reproduced exactly).
  opt.relative_displacement_tolerance = 1e-10;
  return meshopt::optimize_node(P[8], P, tris, opt);
}

}  // namespace

InterpolationData interpolation_data(const TSplineBasis& basis, const std::vector<Eigen::Vector2d>& x,
                                     const BoundaryMap& boundary) {
  const TMesh& mesh = basis.mesh();
  InterpolationData d;
  d.params.reserve(basis.size());
  d.targets.reserve(basis.size());
  for (const BlendingFunction& f : basis.functions()) {
    const Eigen::Vector2d& uv = f.interpolation_point;
    d.params.push_back(uv);
    switch (f.kind) {
      case Kind::Anchor:
        d.targets.push_back(x[f.vertex]);
        break;
      case Kind::EdgeExtra: {
        if (on_border(uv)) {
          // The edge runs along the border (an extra of a corner vertex).
          d.targets.push_back(boundary.point_at(uv));
        } else {
          // The edge from the border vertex through uv ends at 2 uv - anchor.
          const Eigen::Vector2d far = 2.0 * uv - mesh.vertex_param(f.vertex);
          d.targets.push_back(0.5 * (x[f.vertex] + vertex_at(mesh, x, to_ipoint(far))));
        }
        break;
      }
      case Kind::CornerExtra: {
        const int c = basis.locate(uv);
        d.targets.push_back(corner_cell_centre(mesh, c, x, boundary));
        break;
      }
    }
  }
  return d;
}

namespace {

// Solves Eq. 8 for the given interpolation data on map's basis.
// Systems of at most this many functions are solved dense (solve_interpolation).
constexpr int kDenseInterpolation = 96;

void solve_interpolation(TSplineMap& map, const InterpolationData& data, FitReport* report,
                         std::chrono::steady_clock::time_point t0) {
  const TSplineBasis& basis = map.basis();
  const int n = static_cast<int>(basis.size());
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<std::size_t>(n) * 16);
  BasisValues v;
  for (int b = 0; b < n; ++b) {
    basis.evaluate(data.params[b], v, 0);
    for (std::size_t k = 0; k < v.ids.size(); ++k)
      if (v.R[k] != 0.0) trip.emplace_back(b, v.ids[k], v.R[k]);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  A.makeCompressed();
  // Solve for control points relative to the centre of the targets: the
  // functions sum to 1 (Eq. 6), so a translation of all control points
  // translates the map, and far-from-origin coordinates (UTM, say) lose no digits.
  Eigen::Vector2d lo = data.targets.front(), hi = lo;
  for (const Eigen::Vector2d& t : data.targets) lo = lo.cwiseMin(t), hi = hi.cwiseMax(t);
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  Eigen::MatrixX2d rhs(n, 2);
  for (int b = 0; b < n; ++b) rhs.row(b) = (data.targets[b] - centre).transpose();
  auto singular = [n](const std::string& why) {
    return NumericalError("interpolation system (Eq. 8) is singular: the " + std::to_string(n) +
                          " blending functions are linearly dependent on this T-mesh (" + why + ")");
  };
  Eigen::MatrixX2d P;
  if (n <= kDenseInterpolation) {
    // A patch of a layout (16 cells, 49 functions): dense LU with partial
    // pivoting costs a tenth of the sparse one's ordering and analysis.
    const Eigen::MatrixXd dense(A);
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(dense);
    const Eigen::VectorXd u = lu.matrixLU().diagonal();
    for (int k = 0; k < n; ++k)
      if (!(u[k] != 0.0) || !std::isfinite(u[k])) throw singular("zero pivot in column " + std::to_string(k));
    P = lu.solve(rhs);
  } else {
    Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
    lu.compute(A);
    if (lu.info() != Eigen::Success) throw singular(lu.lastErrorMessage());
    P = lu.solve(rhs);
    if (lu.info() != Eigen::Success) throw NumericalError("interpolation system (Eq. 8) could not be solved");
  }
  if (!P.allFinite()) throw NumericalError("interpolation system (Eq. 8) could not be solved");
  std::vector<Eigen::Vector2d> cp(n);
  for (int a = 0; a < n; ++a) cp[a] = P.row(a).transpose() + centre;
  map.set_control_points(std::move(cp));
  // Residual of the interpolation conditions: row b of A holds the functions'
  // values at the interpolation point b, so A P is the map there (relative to
  // the centre; evaluating the map again costs as much as assembling A did).
  const Eigen::MatrixX2d residual = A * P - rhs;
  double res = 0.0;
  for (int b = 0; b < n; ++b) res = std::max(res, residual.row(b).norm());
  const double diag = (hi - lo).norm();
  const double rel = diag > 0 ? res / diag : res;
  if (!(rel <= 1e-8)) {
    std::ostringstream s;
    s << "interpolation system (Eq. 8) is too ill-conditioned: relative residual " << rel;
    throw NumericalError(s.str());
  }
  if (report) {
    report->functions = static_cast<std::size_t>(n);
    report->nonzeros = static_cast<std::size_t>(A.nonZeros());
    report->max_residual = res;
    report->relative_residual = rel;
    report->solve_seconds = toolkit::seconds_since(t0);
  }
}

}  // namespace

TSplineMap fit_tspline(const TMesh& mesh, const std::vector<Eigen::Vector2d>& x, const BoundaryMap& boundary,
                       FitReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  TSplineMap map(mesh);
  solve_interpolation(map, interpolation_data(map.basis(), x, boundary), report, t0);
  return map;
}

TSplineMap interpolate_map(TMesh mesh, const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& target,
                           FitReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  TSplineMap map(std::move(mesh));
  InterpolationData data;
  for (const BlendingFunction& f : map.basis().functions()) {
    data.params.push_back(f.interpolation_point);
    data.targets.push_back(target(f.interpolation_point));
  }
  solve_interpolation(map, data, report, t0);
  return map;
}

TSplineMap transfer_map(const TSplineMap& source, TMesh mesh, FitReport* report) {
  return interpolate_map(
      std::move(mesh), [&source](const Eigen::Vector2d& uv) { return source.point(uv); }, report);
}

}  // namespace tspline
