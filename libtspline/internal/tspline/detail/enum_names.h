#pragma once
// Internal to libtspline, not part of the public interface.
// An enum's names for files and options, in one table that serves both ways:
// value -> name (writing) and name -> value (reading, parsing).
#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

namespace tspline::detail {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

/// The name of `value` in `table`; `fallback` for a value not in it.
template <class E, std::size_t N>
constexpr const char* enum_name(const std::array<EnumName<E>, N>& table, E value, const char* fallback) {
  for (const EnumName<E>& e : table)
    if (e.value == value) return e.name;
  return fallback;
}

/// The value named `name` in `table`; nullopt if none is.
template <class E, std::size_t N>
constexpr std::optional<E> enum_value(const std::array<EnumName<E>, N>& table, std::string_view name) {
  for (const EnumName<E>& e : table)
    if (name == e.name) return e.value;
  return std::nullopt;
}

}  // namespace tspline::detail
