#pragma once
// Internal to libtspline (its I/O), not part of the public interface.
// Groups of .vtu data arrays that several outputs write alike: each struct owns
// its arrays, is filled point by point, and moves them into a VtuMesh under
// their fixed names (the names ParaView users and render.cpp look for).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "toolkit/io/vtu_writer.h"

namespace tspline::detail {

/// The map's quality at sample points: point scalars `mean_ratio_jacobian`,
/// `det_jacobian`, `scaled_jacobian` and the point vector `parametric`.
struct SampleQualityFields {
  std::vector<double> mean_ratio, det, scaled;
  std::vector<Eigen::Vector2d> parametric;

  void reserve(std::size_t n);
  /// n points, to be set by index (zero and (0, 0) until then).
  void resize(std::size_t n);
  /// One sample: the three figures of the Jacobian J at the parametric point uv.
  void push(const Eigen::Matrix2d& J, const Eigen::Vector2d& uv);
  /// Moves the arrays into `out`.
  void attach_to(toolkit::io::VtuMesh& out);
};

/// T-mesh vertices (or points on T-mesh edges) as .vtu points: point ints
/// `hanging` and `boundary` (0 or 1) and the point vector `parametric`.
struct TMeshPointFields {
  std::vector<Eigen::Vector2d> parametric;
  std::vector<int> hanging, boundary;

  void reserve(std::size_t n);
  void push(const Eigen::Vector2d& uv, bool is_hanging, bool on_boundary);
  /// Frees the capacity beyond the points pushed.
  void shrink_to_fit();
  /// Moves the arrays into `out`.
  void attach_to(toolkit::io::VtuMesh& out);
};

}  // namespace tspline::detail
