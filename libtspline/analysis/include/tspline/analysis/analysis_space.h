#pragma once
// The analysis space of the IGA Poisson solver on a map of 1 to n patches
// (poisson_solver.h). A single map is the case n = 1 of the same code.
//
// Per patch: cubic hierarchical B-splines (hierarchical_basis.h) on an ANALYSIS
// T-mesh that refines the patch's geometry T-mesh (PatchSpace); every analysis
// cell lies inside one geometry cell, located once.
//
// Across the interfaces (patch_layout.h): the two patches of a cut carry the
// same border knots (multipatch_parameterization.h, and refine_conforming in
// poisson_adaptive.h keeps them so), so the traces of their border functions
// on the cut are the same univariate hierarchical B-splines. The function of
// level l with tangential index k on side_a is glued to the one of level l
// with index 2^l + 2 - k on side_b (the cut is traversed the other way): one
// global unknown per glued pair (or group, at a node shared by several
// patches). The glued space is continuous across the cuts (C0).
//
// Global numbering: patch by patch, function by function, a function takes
// the number of its glued group if an earlier function of the group has one,
// else the next number. With one patch the global number of function a is a.
// The DIRICHLET functions are those non-zero on a patch side that is not an
// interface (a ring of the domain: its outer boundary or a hole).
//
// Cells are numbered globally patch by patch: cell c of patch p is
// cell_offset(p) + c.
//
// Distribution over P processes (rank r): the global cells are split into P
// contiguous blocks, [r nc / P, (r+1) nc / P) for rank r (block()); a process
// HOLDS the spaces (T-mesh and basis) of the patches its block touches and of
// their neighbours (patches sharing an interface or a layout node with them:
// the other patches of every glued DOF of its patches), not the others. Every
// process keeps every patch's analysis T-mesh and the global numbering of
// every function (4 bytes each); the bases of the other patches are built
// once, for their border functions (gluing, Dirichlet DOFs), and dropped.
// With one patch every process holds it (the rows are then split by cells:
// petsc_solver.h).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "tspline/analysis/hierarchical_basis.h"
#include "tspline/multipatch/patch_layout.h"
#include "tspline/spline/tspline_map.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// The geometry of an analysis: the patch maps and the interfaces between
/// them (one patch and no interfaces for a single map). The maps must outlive
/// every space and solution made on them.
struct AnalysisGeometry {
  std::vector<const TSplineMap*> patches;
  std::vector<Interface> interfaces;

  AnalysisGeometry() = default;
  explicit AnalysisGeometry(const TSplineMap& map) : patches{&map} {}
  AnalysisGeometry(std::vector<const TSplineMap*> maps, std::vector<Interface> cuts)
      : patches(std::move(maps)), interfaces(std::move(cuts)) {}

  std::size_t size() const { return patches.size(); }
  const TSplineMap& patch(std::size_t p) const { return *patches[p]; }
  /// The analysis meshes of the first step: the geometry T-meshes refined
  /// (conformingly, refine_conforming) until no knot line of a patch's
  /// geometry functions crosses a cell, so that every cell lies in one Bezier
  /// element of its map (bezier_extraction.h) and u o S is as smooth on a cell
  /// as the analysis functions are. (From the geometry T-meshes themselves,
  /// whose cells such lines cross near T-junctions, the analysis functions are
  /// polynomial where u o S is only C^2, and the first refinements are
  /// pre-asymptotic: measured on a sea's layout, L2 rates 2.5, 5.4, 5.1 and H1
  /// 1.7, 4.4, 3.9.)
  std::vector<TMesh> meshes() const;
};

/// Splits cells[p] of meshes[p] (cells to split, e.g. a refinement_patch), then
/// makes the interfaces conforming again: both sides of each cut are refined
/// to the union of their border knots (mirrored), repeatedly, until no side
/// changes. Returns the number of cells split beyond `cells` by that propagation.
std::size_t refine_conforming(std::vector<TMesh>& meshes, const std::vector<Interface>& interfaces,
                              const std::vector<std::vector<int>>& cells);

/// One patch's analysis space: T-mesh, its basis, and per analysis cell its geometry cell.
class PatchSpace {
 public:
  /// \pre analysis_mesh has topology and refines map.mesh() (each cell inside one
  /// geometry cell). \throw InputError otherwise.
  PatchSpace(const TSplineMap& map, TMesh analysis_mesh);
  const TMesh& mesh() const { return *mesh_; }
  const HierarchicalBasis& basis() const { return *basis_; }
  int geometry_cell(int c) const { return geometry_cell_[c]; }
  std::size_t num_functions() const { return basis_->size(); }

 private:
  std::unique_ptr<TMesh> mesh_;  // heap: the basis keeps a pointer to it
  std::unique_ptr<HierarchicalBasis> basis_;
  std::vector<int> geometry_cell_;
};

/// Tangential index (in the side's own direction, boundary_map.h) of a
/// function that does not vanish on `side` of its patch, or -1 if it vanishes there.
std::int64_t side_index(const HierarchicalFunction& f, int side);

/// The glued space of all patches (see the file comment).
class AnalysisSpace {
 public:
  /// One patch: the space of a single map.
  AnalysisSpace(const TSplineMap& map, TMesh analysis_mesh);
  /// \param meshes per patch an analysis T-mesh refining the patch's geometry T-mesh.
  /// \param rank, processes: this process and their number (see the file comment).
  /// \throw InputError (a mesh that does not refine its patch's, a count that
  /// does not match); NumericalError if an interface is not conforming (a
  /// border function without partner on the other side).
  AnalysisSpace(AnalysisGeometry geometry, std::vector<TMesh> meshes, int rank = 0, int processes = 1);

  /// The same space with every patch held (the built ones shared).
  std::shared_ptr<const AnalysisSpace> completed() const;

  const AnalysisGeometry& geometry() const { return geometry_; }
  const TSplineMap& map(std::size_t p) const { return geometry_.patch(p); }
  std::size_t num_patches() const { return patches_.size(); }
  /// Whether this process holds patch p's space; every patch when processes = 1.
  bool holds(std::size_t p) const { return patches_[p] != nullptr; }
  bool holds_all() const;
  /// \pre holds(p).
  const PatchSpace& patch(std::size_t p) const;
  /// Patch p's space: the one held, or one built now (not kept).
  std::shared_ptr<const PatchSpace> patch_space(std::size_t p) const;
  /// Patch p's analysis T-mesh (every patch).
  const TMesh& mesh(std::size_t p) const { return holds(p) ? patches_[p]->mesh() : meshes_[p]; }
  /// Global cells [first, last) of the block of `rank` (of processes()).
  std::pair<std::size_t, std::size_t> block(int rank) const;
  int rank() const { return rank_; }
  int processes() const { return processes_; }

  /// Global unknowns (glued functions, Dirichlet ones included).
  std::size_t num_dofs() const { return num_dofs_; }
  /// Global number of function a of patch p.
  int dof(std::size_t p, int a) const { return dofs_[p][a]; }
  std::span<const int> dofs(std::size_t p) const { return dofs_[p]; }
  /// Whether global DOF g is non-zero on the domain's boundary (a Dirichlet DOF).
  bool is_dirichlet(int g) const { return dirichlet_[g] != 0; }
  /// (function, function) pairs identified across the interfaces.
  std::size_t glued_pairs() const { return glued_pairs_; }
  /// Whether side `side` of patch p is an interface (else a ring: Dirichlet).
  bool is_interface_side(std::size_t p, int side) const { return interface_side_[p][side] != 0; }

  /// Cells of every patch.
  std::size_t num_cells() const { return cell_offset_.back(); }
  std::size_t cell_offset(std::size_t p) const { return cell_offset_[p]; }
  /// (patch, cell of the patch) of global cell gc.
  std::pair<std::size_t, int> cell(std::size_t gc) const;
  /// Global DOFs of the functions of global cell gc, in the order of the
  /// patch's basis().functions_on_cell (not sorted). \pre holds(its patch).
  void cell_dofs(std::size_t gc, std::vector<int>& out) const;

 private:
  AnalysisSpace() = default;
  AnalysisGeometry geometry_;
  std::vector<std::shared_ptr<const PatchSpace>> patches_;  // null: not held
  std::vector<TMesh> meshes_;  // the T-meshes of the patches not held (empty for the others)
  int rank_ = 0, processes_ = 1;
  std::vector<std::vector<int>> dofs_;
  std::vector<char> dirichlet_;
  std::vector<std::array<char, 4>> interface_side_;
  std::vector<std::size_t> cell_offset_;
  std::size_t num_dofs_ = 0;
  std::size_t glued_pairs_ = 0;
};

}  // namespace tspline
