#pragma once
// Points of an output mesh by their parametric position: one point per
// position however many cells sample it (the VTU writers of a T-mesh's cells).
// An open-addressing table of point numbers, hashed by the bits of the two
// doubles (+0 for -0; positions are finite): no allocation per point, as a
// node-based map would make.
#include <Eigen/Core>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace tspline::detail {

class UvPointIndex {
 public:
  /// `expected`: about how many points will be added (the table grows past it).
  explicit UvPointIndex(std::size_t expected) : slots_(std::bit_ceil(2 * expected + 16), -1) {
    uv_.reserve(expected);
  }

  /// The point at uv: (its number, false) if it was added before, else
  /// (size(), true) and uv is added as that point.
  std::pair<int, bool> find_or_add(const Eigen::Vector2d& uv) {
    if (2 * (uv_.size() + 1) > slots_.size()) grow();
    const std::size_t mask = slots_.size() - 1;
    std::size_t i = hash(uv) & mask;
    for (; slots_[i] >= 0; i = (i + 1) & mask)
      if (uv_[slots_[i]].x() == uv.x() && uv_[slots_[i]].y() == uv.y()) return {slots_[i], false};
    slots_[i] = static_cast<int>(uv_.size());
    uv_.push_back(uv);
    return {slots_[i], true};
  }

  std::size_t size() const { return uv_.size(); }

 private:
  // The table uses the hash's low bits, and dyadic positions have none in
  // their mantissas: every bit is mixed into them (splitmix64's finalizer).
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  static std::size_t hash(const Eigen::Vector2d& uv) {
    const std::uint64_t a = std::bit_cast<std::uint64_t>(uv.x() + 0.0);
    const std::uint64_t b = std::bit_cast<std::uint64_t>(uv.y() + 0.0);
    return static_cast<std::size_t>(mix(a ^ mix(b + 0x9E3779B97F4A7C15ull)));
  }

  void grow() {
    slots_.assign(2 * slots_.size(), -1);
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t p = 0; p < uv_.size(); ++p) {
      std::size_t i = hash(uv_[p]) & mask;
      while (slots_[i] >= 0) i = (i + 1) & mask;
      slots_[i] = static_cast<int>(p);
    }
  }

  std::vector<int> slots_;
  std::vector<Eigen::Vector2d> uv_;
};

}  // namespace tspline::detail
