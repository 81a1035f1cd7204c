#include "tspline/layout/layout_mesh.h"

#include <algorithm>
#include <unordered_map>

namespace tspline {

LayoutTopology::LayoutTopology(const LayoutMesh& m)
    : corners_(m.size()), on_ring_(4 * m.quads.size(), 0), across_(4 * m.quads.size(), {-1, -1}) {
  std::unordered_map<unsigned long long, std::pair<int, int>> first;  // undirected edge -> (quad, index)
  first.reserve(4 * m.quads.size());
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    for (int j = 0; j < 4; ++j) {
      corners_[m.quads[q][j]].push_back({static_cast<int>(q), j});
      const int a = m.quads[q][j], b = m.quads[q][(j + 1) % 4];
      const unsigned long long key = (static_cast<unsigned long long>(std::min(a, b)) << 32) |
                                     static_cast<unsigned long long>(std::max(a, b));
      const auto [it, fresh] = first.try_emplace(key, static_cast<int>(q), j);
      if (!fresh) {
        across_[4 * q + j] = it->second;
        across_[4 * static_cast<std::size_t>(it->second.first) + it->second.second] = {static_cast<int>(q), j};
      }
    }
  for (std::size_t k = 0; k < across_.size(); ++k) on_ring_[k] = across_[k].first < 0;
}

}  // namespace tspline
