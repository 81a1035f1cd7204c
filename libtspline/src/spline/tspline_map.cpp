#include "tspline/spline/tspline_map.h"

#include <stdexcept>
#include <string>
#include "toolkit/errors.h"

namespace tspline {

TSplineMap::TSplineMap(TMesh mesh, std::vector<Eigen::Vector2d> control_points)
    : mesh_(std::make_unique<TMesh>(std::move(mesh))),
      basis_(std::make_unique<TSplineBasis>(*mesh_)),
      control_points_(std::move(control_points)) {
  if (control_points_.size() != basis_->size())
    throw toolkit::InputError("TSplineMap: " + std::to_string(control_points_.size()) + " control points for " +
                                std::to_string(basis_->size()) + " blending functions");
}

TSplineMap::TSplineMap(TMesh mesh)
    : mesh_(std::make_unique<TMesh>(std::move(mesh))),
      basis_(std::make_unique<TSplineBasis>(*mesh_)),
      control_points_(basis_->size(), Eigen::Vector2d::Zero()) {}

void TSplineMap::set_control_points(std::vector<Eigen::Vector2d> control_points) {
  if (control_points.size() != basis_->size())
    throw toolkit::InputError("TSplineMap: " + std::to_string(control_points.size()) + " control points for " +
                                std::to_string(basis_->size()) + " blending functions");
  control_points_ = std::move(control_points);
}

TSplineMap::TSplineMap(const TSplineMap& o)
    : mesh_(std::make_unique<TMesh>(*o.mesh_)),
      basis_(std::make_unique<TSplineBasis>(*o.basis_, *mesh_)),
      control_points_(o.control_points_) {}

TSplineMap& TSplineMap::operator=(const TSplineMap& o) {
  if (this != &o) *this = TSplineMap(o);
  return *this;
}

MapDerivatives TSplineMap::derivatives(const Eigen::Vector2d& uv, int order, int c) const {
  thread_local BasisValues v;
  if (c < 0) c = basis_->locate(uv);
  basis_->evaluate(c, uv, v, order);
  MapDerivatives d;
  for (std::size_t k = 0; k < v.ids.size(); ++k) {
    const Eigen::Vector2d& P = control_points_[v.ids[k]];
    d.x += v.R[k] * P;
    if (order >= 1) {
      d.J.col(0) += v.R_xi[k] * P;
      d.J.col(1) += v.R_eta[k] * P;
    }
    if (order >= 2) {
      d.xixi += v.R_xixi[k] * P;
      d.xieta += v.R_xieta[k] * P;
      d.etaeta += v.R_etaeta[k] * P;
    }
  }
  return d;
}

TSplineMap greville_identity_map(TMesh mesh) {
  TSplineMap map(std::move(mesh));
  std::vector<Eigen::Vector2d> P;
  P.reserve(map.basis().size());
  for (const BlendingFunction& f : map.basis().functions())
    P.emplace_back((f.knots_xi[1] + f.knots_xi[2] + f.knots_xi[3]) / 3.0,
                   (f.knots_eta[1] + f.knots_eta[2] + f.knots_eta[3]) / 3.0);
  map.set_control_points(std::move(P));
  return map;
}

Eigen::Vector2d TSplineMap::point(const Eigen::Vector2d& uv) const { return derivatives(uv, 0).x; }

Eigen::Matrix2d TSplineMap::jacobian(const Eigen::Vector2d& uv) const { return derivatives(uv, 1).J; }

}  // namespace tspline
