#pragma once
// What one quad layout of a domain can take from an earlier layout of the
// same domain (QuadLayoutOptions::memo, quad_layout.h): the quad mesher's
// quads for the same ring nodes, and the first pass of the layout
// optimization (K* untangling, a short node optimization, edge rotations) of
// the same mesh. Both depend only on the domain, the size field's options, the
// ring nodes, the optimization level and whether node moves may put patch
// corners out of range, so the result is the one the work itself gives (the
// pillowed second layout of parameterize_domain starts from the first's ring
// nodes: its first mesh and first pass are the first layout's).
//
// A memo serves the domain and size options it was first used with; a call
// for another domain is neither served nor stored. Safe to use from several
// threads.
#include <Eigen/Core>
#include <cstddef>
#include <mutex>
#include <optional>
#include <vector>

#include "tspline/layout/layout_mesh.h"
#include "tspline/layout/quad_mesher.h"
#include "tspline/layout/size_field.h"

namespace tspline {

/// The first pass of the layout optimization: the mesh it leaves and its counts.
struct LayoutFirstPass {
  LayoutMesh mesh;
  std::size_t rotations = 0;
  int optimization_sweeps = 0;
};

class QuadLayoutMemo {
 public:
  using Rings = std::vector<std::vector<Eigen::Vector2d>>;
  using RingNodes = std::vector<std::vector<double>>;

  std::optional<PlanarQuadMesh> mesh(const Rings& domain, const SizeFieldOptions& size,
                                     const RingNodes& nodes);
  void store_mesh(const Rings& domain, const SizeFieldOptions& size, const RingNodes& nodes,
                  const PlanarQuadMesh& mesh);

  std::optional<LayoutFirstPass> first_pass(const Rings& domain, const SizeFieldOptions& size,
                                            const RingNodes& nodes, int level, bool guard_corners,
                                            double max_corner_degrees);
  void store_first_pass(const Rings& domain, const SizeFieldOptions& size, const RingNodes& nodes, int level,
                        bool guard_corners, double max_corner_degrees, const LayoutFirstPass& pass);

  /// Lookups that found an entry (for tests and debugging output).
  std::size_t hits() const;

 private:
  // Whether calls for (domain, size) may use this memo: the first call binds it.
  bool serves(const Rings& domain, const SizeFieldOptions& size);

  struct MeshEntry {
    RingNodes nodes;
    PlanarQuadMesh mesh;
  };
  struct PassEntry {
    RingNodes nodes;
    int level = 0;
    bool guard_corners = false;
    // QuadLayoutOptions::max_patch_corner_degrees (the rotations keep to it).
    double max_corner_degrees = 0.0;
    LayoutFirstPass pass;
  };
  mutable std::mutex mutex_;
  std::optional<Rings> domain_;
  SizeFieldOptions size_;
  std::vector<MeshEntry> meshes_;
  std::vector<PassEntry> passes_;
  std::size_t hits_ = 0;
};

}  // namespace tspline
