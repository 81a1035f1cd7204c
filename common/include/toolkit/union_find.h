#pragma once
// Disjoint sets of the indices 0..n-1 (union-find with path halving). The root
// of a set is always its smallest index, so that code numbering the sets "in
// order of first occurrence" may use the root itself.
#include <cstddef>
#include <numeric>
#include <utility>
#include <vector>

namespace toolkit {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), std::size_t{0}); }

  /// The root (smallest index) of the set of x.
  std::size_t find(std::size_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }

  /// Joins the sets of a and b; false if they were one set already.
  bool unite(std::size_t a, std::size_t b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    if (b < a) std::swap(a, b);
    parent_[b] = a;
    return true;
  }

  bool same(std::size_t a, std::size_t b) { return find(a) == find(b); }
  std::size_t size() const { return parent_.size(); }

 private:
  std::vector<std::size_t> parent_;
};

}  // namespace toolkit
