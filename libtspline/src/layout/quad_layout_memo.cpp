#include "tspline/layout/quad_layout_memo.h"

#include "tspline/layout/quad_layout.h"

namespace tspline {

std::shared_ptr<QuadLayoutMemo> make_quad_layout_memo() { return std::make_shared<QuadLayoutMemo>(); }

bool QuadLayoutMemo::serves(const Rings& domain, const SizeFieldOptions& size) {
  if (!domain_) {
    domain_ = domain;
    size_ = size;
    return true;
  }
  return size_ == size && *domain_ == domain;
}

std::optional<PlanarQuadMesh> QuadLayoutMemo::mesh(const Rings& domain, const SizeFieldOptions& size,
                                                   const RingNodes& nodes) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!serves(domain, size)) return std::nullopt;
  for (const MeshEntry& e : meshes_)
    if (e.nodes == nodes) {
      ++hits_;
      return e.mesh;
    }
  return std::nullopt;
}

void QuadLayoutMemo::store_mesh(const Rings& domain, const SizeFieldOptions& size, const RingNodes& nodes,
                                const PlanarQuadMesh& mesh) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!serves(domain, size)) return;
  for (const MeshEntry& e : meshes_)
    if (e.nodes == nodes) return;
  meshes_.push_back({nodes, mesh});
}

std::optional<LayoutFirstPass> QuadLayoutMemo::first_pass(const Rings& domain, const SizeFieldOptions& size,
                                                          const RingNodes& nodes, int level,
                                                          bool guard_corners, double max_corner_degrees) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!serves(domain, size)) return std::nullopt;
  for (const PassEntry& e : passes_)
    if (e.level == level && e.guard_corners == guard_corners && e.max_corner_degrees == max_corner_degrees &&
        e.nodes == nodes) {
      ++hits_;
      return e.pass;
    }
  return std::nullopt;
}

void QuadLayoutMemo::store_first_pass(const Rings& domain, const SizeFieldOptions& size,
                                      const RingNodes& nodes, int level, bool guard_corners,
                                      double max_corner_degrees, const LayoutFirstPass& pass) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!serves(domain, size)) return;
  for (const PassEntry& e : passes_)
    if (e.level == level && e.guard_corners == guard_corners && e.max_corner_degrees == max_corner_degrees &&
        e.nodes == nodes)
      return;
  passes_.push_back({nodes, level, guard_corners, max_corner_degrees, pass});
}

std::size_t QuadLayoutMemo::hits() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return hits_;
}

}  // namespace tspline
