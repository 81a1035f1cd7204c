#pragma once
// Cubic hierarchical B-splines on a balanced quadtree T-mesh: the analysis space
// of the Poisson solver (poisson.h).
//
// Why not the T-spline blending functions of tspline_basis.h: on a T-mesh with
// hanging vertices the normalized functions R = N / sum N do not reproduce even
// linear functions near the T-junctions (measured in tests/analysis/test_hierarchical_basis.cpp),
// and refinement does not give nested spaces, so Galerkin errors decay at about
// h^2 (L2) and h (H1) instead of h^4 and h^3. Hierarchical B-splines on the same
// quadtree contain every cubic polynomial, are nested under refinement, and are
// polynomial on each cell (Gauss quadrature over a cell is exact for polynomial
// data; no knot line crosses a cell).
//
// Construction (Kraft 1997; Vuong, Giannelli, Juettler, Simeon, CMAME 200, 2011):
// level l has the tensor-product cubic B-splines B^l_{ij} with open knot vectors
// on the uniform grid of 2^l x 2^l cells of [0,1]^2 (indices i, j in
// [0, 2^l + 2]; knots {i-3, ..., i+1} / 2^l clamped to [0, 1]). With Omega^l the
// union of the T-mesh cells of level >= l (nested: Omega^0 = [0,1]^2), B^l_{ij} is
// ACTIVE iff supp B ⊆ Omega^l and supp B ⊄ Omega^{l+1}, i.e. every level-l cell
// of its support is a node of the quadtree and at least one of them is a leaf.
// The active functions are linearly independent and span the hierarchical space
// (which equals the THB-spline space; this basis is not truncated, so it is not a
// partition of unity, which the Galerkin method does not need).
//
// Boundary: with open knot vectors only the functions with i or j equal to 0 or
// 2^l + 2 are non-zero on the border of [0,1]^2 (on_border()). Their traces are
// a 1D hierarchical basis on each side, hence linearly independent.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "tspline/tmesh/tmesh.h"
#include "tspline/spline/tspline_basis.h"

namespace tspline {

/// One active function B^level_{ix,iy}(xi, eta) = N[knots_xi](xi) N[knots_eta](eta).
struct HierarchicalFunction {
  int level = 0;
  std::int64_t ix = 0, iy = 0;  ///< indices in [0, 2^level + 2]
  std::array<double, 5> knots_xi{};
  std::array<double, 5> knots_eta{};
  bool on_border = false;  ///< non-zero somewhere on the border of [0,1]^2
};

class HierarchicalBasis {
 public:
  /// \pre mesh.has_topology(). The mesh must outlive the basis.
  explicit HierarchicalBasis(const TMesh& mesh);

  std::size_t size() const { return functions_.size(); }
  const HierarchicalFunction& function(int a) const { return functions_[a]; }

  /// Active functions non-zero on the interior of cell c (sorted by id).
  std::span<const int> functions_on_cell(int c) const {
    return {cell_ids_.data() + cell_offset_[c], cell_ids_.data() + cell_offset_[c + 1]};
  }

  /// Cell containing the parametric point (same convention as TSplineBasis::locate).
  int locate(const Eigen::Vector2d& uv) const;

  /// Values and derivatives up to `order` (0, 1 or 2) of the functions of cell c
  /// at uv (fields R, R_xi, ... hold N and its derivatives; nothing is normalized).
  void evaluate(int c, const Eigen::Vector2d& uv, BasisValues& out, int order = 2) const;

  const TMesh& mesh() const { return *mesh_; }

 private:
  const TMesh* mesh_;
  std::vector<HierarchicalFunction> functions_;
  std::vector<std::size_t> cell_offset_;  // CSR: cell c's ids are cell_ids_[offset[c], offset[c+1])
  std::vector<int> cell_ids_;
};

}  // namespace tspline
