#include "tspline/detail/vtu_fields.h"

#include <Eigen/LU>
#include <utility>

#include "tspline/validity/map_quality.h"

namespace tspline::detail {

void SampleQualityFields::reserve(std::size_t n) {
  mean_ratio.reserve(n), det.reserve(n), scaled.reserve(n), parametric.reserve(n);
}

void SampleQualityFields::resize(std::size_t n) {
  mean_ratio.resize(n), det.resize(n), scaled.resize(n), parametric.resize(n, Eigen::Vector2d::Zero());
}

void SampleQualityFields::push(const Eigen::Matrix2d& J, const Eigen::Vector2d& uv) {
  mean_ratio.push_back(mean_ratio_jacobian(J));
  det.push_back(J.determinant());
  scaled.push_back(scaled_jacobian(J));
  parametric.push_back(uv);
}

void SampleQualityFields::attach_to(toolkit::io::VtuMesh& out) {
  out.point_scalars["mean_ratio_jacobian"] = std::move(mean_ratio);
  out.point_scalars["det_jacobian"] = std::move(det);
  out.point_scalars["scaled_jacobian"] = std::move(scaled);
  out.point_vectors["parametric"] = std::move(parametric);
}

void TMeshPointFields::reserve(std::size_t n) {
  parametric.reserve(n), hanging.reserve(n), boundary.reserve(n);
}

void TMeshPointFields::push(const Eigen::Vector2d& uv, bool is_hanging, bool on_boundary) {
  parametric.push_back(uv);
  hanging.push_back(is_hanging ? 1 : 0);
  boundary.push_back(on_boundary ? 1 : 0);
}

void TMeshPointFields::shrink_to_fit() {
  parametric.shrink_to_fit(), hanging.shrink_to_fit(), boundary.shrink_to_fit();
}

void TMeshPointFields::attach_to(toolkit::io::VtuMesh& out) {
  out.point_vectors["parametric"] = std::move(parametric);
  out.point_ints["hanging"] = std::move(hanging);
  out.point_ints["boundary"] = std::move(boundary);
}

}  // namespace tspline::detail
