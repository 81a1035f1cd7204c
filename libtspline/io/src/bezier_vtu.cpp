#include "tspline/io/bezier_vtu.h"

#include <Eigen/LU>
#include <array>

#include "tspline/detail/vtu_fields.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/element_map.h"
#include "tspline/validity/map_quality.h"

namespace tspline::io {
namespace {

using Matrix4 = Eigen::Matrix4d;

/// M(a, i) = B_i(a / 3): the cubic Bernstein polynomials at the equispaced
/// points 0, 1/3, 2/3, 1 (invertible: Bernstein collocation at distinct points).
Matrix4 equispaced_bernstein() {
  Matrix4 M;
  for (int a = 0; a < 4; ++a) {
    const std::array<double, 4> b = bernstein3(a / 3.0);
    for (int i = 0; i < 4; ++i) M(a, i) = b[i];
  }
  return M;
}

/// Whether each element of `extraction` is certified: from a given certificate
/// of the same map, or certified here.
std::vector<int> element_certified(const TSplineMap& map, const BezierExtraction& extraction,
                                   const MapCertification* given, const CertificationOptions& options) {
  const std::size_t n = extraction.elements().size();
  MapCertification own;
  if (!given || given->elements != n) {
    own = certify_map(extraction, map.mesh().num_cells(), map.control_points(), options);
    given = &own;
  }
  std::vector<int> certified(n, 1);
  for (const CertificationFailure& f : given->failures) certified[f.element] = 0;
  return certified;
}

}  // namespace

int vtk_bezier_quad_index(int i, int j) {
  // vtkHigherOrderQuadrilateral::PointIndexFromIJK for order (3, 3).
  const bool ib = i == 0 || i == 3, jb = j == 0 || j == 3;
  if (ib && jb) return i ? (j ? 2 : 1) : (j ? 3 : 0);  // corners
  if (jb) return 4 + (i - 1) + (j ? 4 : 0);            // edges along s: t = 0, then t = 1
  if (ib) return 4 + (j - 1) + (i ? 2 : 6);            // edges along t: s = 1, then s = 0
  return 12 + (i - 1) + 2 * (j - 1);                   // interior
}

toolkit::io::VtuMesh bezier_vtu(const TSplineMap& map, const MapCertification* certification,
                                const CertificationOptions& options, const BezierExtraction* given) {
  const ExtractionOrOwn extraction_or_own(map.basis(), given);
  const BezierExtraction& extraction = extraction_or_own.get();
  const std::vector<BezierElement>& elements = extraction.elements();
  const std::vector<Eigen::Vector2d>& P = map.control_points();
  const std::vector<int> certified = element_certified(map, extraction, certification, options);
  const Matrix4 M = equispaced_bernstein();
  const Matrix4 Minv = M.inverse();

  toolkit::io::VtuMesh out;
  const std::size_t np = 16 * elements.size();
  out.points.resize(np);
  std::vector<double> weight(np);
  detail::SampleQualityFields quality;
  quality.resize(np);
  std::vector<Eigen::Vector2d> lo, hi;
  std::vector<int> cell, level, patch;
  out.cells.reserve(elements.size()), out.cell_types.reserve(elements.size());
  out.higher_order_degrees.reserve(elements.size());
  cell.reserve(elements.size()), level.reserve(elements.size()), patch.reserve(elements.size());
  lo.reserve(elements.size()), hi.reserve(elements.size());
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const BezierElement& el = elements[e];
    const Eigen::Matrix<double, 16, 3> H = homogeneous_bezier_points(el, P);  // (X_k, w_k), k = i + 4 j
    Matrix4 w;  // w(i, j) of B_i(s) B_j(t)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) w(i, j) = H(i + 4 * j, 2);
    // The fields at the 4 x 4 equispaced points, and W = sum w_k B_k there.
    const Matrix4 W = M * w * M.transpose();  // W(a, b) at (s, t) = (a/3, b/3)
    std::array<Matrix4, 5> F;                 // J_r, det J, scaled Jacobian, xi, eta
    const ElementMap element_map(el, P);
    for (int b = 0; b < 4; ++b)
      for (int a = 0; a < 4; ++a) {
        const Eigen::Vector2d uv = el.lo + Eigen::Vector2d(a / 3.0, b / 3.0).cwiseProduct(el.hi - el.lo);
        const Eigen::Matrix2d J = element_map.at_local(a / 3.0, b / 3.0).J;
        F[0](a, b) = mean_ratio_jacobian(J), F[1](a, b) = J.determinant(), F[2](a, b) = scaled_jacobian(J);
        F[3](a, b) = uv.x(), F[4](a, b) = uv.y();
      }
    // Coefficients d with sum_k w_k B_k d_k / W = f at those points:
    // M (w .* d) M^T = W .* F.
    std::array<Matrix4, 5> D;
    for (int f = 0; f < 5; ++f) D[f] = (Minv * W.cwiseProduct(F[f]) * Minv.transpose()).cwiseQuotient(w);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const std::size_t q = 16 * e + static_cast<std::size_t>(vtk_bezier_quad_index(i, j));
        const int k = i + 4 * j;
        out.points[q] = Eigen::Vector2d(H(k, 0), H(k, 1)) / H(k, 2);
        weight[q] = H(k, 2);
        quality.mean_ratio[q] = D[0](i, j), quality.det[q] = D[1](i, j), quality.scaled[q] = D[2](i, j);
        quality.parametric[q] = {D[3](i, j), D[4](i, j)};
      }
    std::vector<int> ids(16);
    for (int k = 0; k < 16; ++k) ids[k] = static_cast<int>(16 * e) + k;
    out.cells.push_back(std::move(ids));
    out.cell_types.push_back(kVtkBezierQuadrilateral);
    out.higher_order_degrees.push_back({3, 3, 0});
    cell.push_back(el.cell);
    level.push_back(map.mesh().cell_level(el.cell));
    patch.push_back(0);
    lo.push_back(el.lo), hi.push_back(el.hi);
  }
  out.point_scalars["RationalWeights"] = std::move(weight);
  out.rational_weights = "RationalWeights";
  quality.attach_to(out);
  out.cell_ints["patch"] = std::move(patch);
  out.cell_ints["cell"] = std::move(cell);
  out.cell_ints["level"] = std::move(level);
  out.cell_ints["certified"] = certified;
  out.cell_vectors["parametric_lo"] = std::move(lo);
  out.cell_vectors["parametric_hi"] = std::move(hi);
  return out;
}

}  // namespace tspline::io
