#pragma once
// The map exactly, for ParaView (surface_bezier.vtu, `tspline export
// --vtk-bezier`): one rational bicubic Bezier cell per Bezier element
// (bezier_extraction.h), VTK 9's VTK_BEZIER_QUADRILATERAL with degrees (3, 3)
// (cell data HigherOrderDegrees) and the weights as point data
// RationalWeights. On an element the map is S = X / w with X and w bicubic
// polynomials in the Bernstein basis (bezier_export.h): the cell's 16 points
// are the Bezier points X_k / w_k, their weights w_k, so VTK's rational
// Bernstein interpolation sum_k w_k B_k x_k / sum_k w_k B_k is S itself, and
// ParaView draws the curved cells, the exact boundary and the map's own
// continuity at any zoom (tessellated by its "Nonlinear Subdivision Level").
//
// Every cell has its own 16 points, in VTK's order for higher-order
// quadrilaterals: the corners (0,0), (1,0), (1,1), (0,1), then the inner
// points of the edges s = 0..1 at t = 0, s = 1, t = 1 (s increasing), s = 0,
// then the interior row by row.
//
// Point data, interpolated by VTK with the same rational basis:
// mean_ratio_jacobian (J_r), det_jacobian, scaled_jacobian and parametric
// (xi, eta). These are not rational bicubics, so their coefficients are chosen
// so that VTK's interpolant equals them exactly at the 4 x 4 equispaced points
// of each element (corners included; in between it is an approximation). Cell
// data: patch, cell (T-mesh cell), level, certified (1 if det J > 0 is
// certified on the element, map_certification.h), parametric_lo and
// parametric_hi (the element's parametric box).
#include "toolkit/io/vtu_writer.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/tspline_map.h"
#include "tspline/validity/map_certification.h"

namespace tspline::io {

/// VTK's cell type number of VTK_BEZIER_QUADRILATERAL.
inline constexpr int kVtkBezierQuadrilateral = 77;

/// The position of the Bernstein coefficient (i, j) (B_i(s) B_j(t), i, j in
/// 0..3) among the 16 points of a bicubic VTK higher-order quadrilateral.
int vtk_bezier_quad_index(int i, int j);

/// The cells of `map` as above. `certification`: the map's certificate if
/// already computed (certify_map on the same map, every failure listed); else
/// the elements are certified here with `options`. `extraction`: the map's
/// Bezier extraction, if made already.
toolkit::io::VtuMesh bezier_vtu(const TSplineMap& map, const MapCertification* certification = nullptr,
                                const CertificationOptions& options = {},
                                const BezierExtraction* extraction = nullptr);

}  // namespace tspline::io
