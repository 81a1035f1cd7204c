#pragma once
// Helpers shared by the test suites.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "tspline/polygon.h"

namespace test_support {

/// Path of a bundled test polygon, e.g. polygon_file("disk.txt").
inline std::string polygon_file(const std::string& file_name) {
  return std::string(TSPLINE_TEST_DATA_DIR) + "/polygons/" + file_name;
}

/// A polygon with the identity file numbering.
inline tspline::Polygon make_polygon(const std::vector<Eigen::Vector2d>& v) {
  tspline::Polygon p;
  p.vertices = v;
  for (std::size_t i = 0; i < v.size(); ++i) p.file_index.push_back(i);
  return p;
}

/// The message of the exception of type E thrown by f (fails the test if none).
template <class E, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  FAIL("no exception of the expected type");
  return {};
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace test_support
