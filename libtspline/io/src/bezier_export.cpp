#include "tspline/io/bezier_export.h"

#include "tspline/spline/bezier_extraction.h"

namespace tspline::io {

nlohmann::json bezier_document(const TSplineMap& map, const std::string& source) {
  using nlohmann::json;
  const BezierExtraction extraction(map.basis());
  const auto& P = map.control_points();
  json points = json::array();
  for (const Eigen::Vector2d& p : P) points.push_back({p.x(), p.y()});
  json elements = json::array();
  for (const BezierElement& e : extraction.elements()) {
    json rows = json::array();
    for (std::size_t r = 0; r < e.functions.size(); ++r) {
      const auto row = e.C.row(static_cast<Eigen::Index>(r));
      rows.push_back(std::vector<double>(row.data(), row.data() + 16));
    }
    const Eigen::Matrix<double, 16, 3> H = homogeneous_bezier_points(e, P);
    json hom = json::array();
    for (int k = 0; k < 16; ++k) hom.push_back({H(k, 0), H(k, 1), H(k, 2)});
    elements.push_back({{"cell", e.cell},
                        {"lo", {e.lo.x(), e.lo.y()}},
                        {"hi", {e.hi.x(), e.hi.y()}},
                        {"functions", e.functions},
                        {"extraction", std::move(rows)},
                        {"bezier_points_homogeneous", std::move(hom)}});
  }
  return {{"format", "tspline-bezier"},
          {"version", 1},
          {"degree", {3, 3}},
          {"source", source},
          {"parametric_domain", {{0, 0}, {1, 1}}},
          {"map", "S = (sum_a P_a N_a) / (sum_a N_a)"},
          {"bernstein_order", "k = i + 4 j for B_i(s) B_j(t)"},
          {"control_points", std::move(points)},
          {"elements", std::move(elements)}};
}

}  // namespace tspline::io
