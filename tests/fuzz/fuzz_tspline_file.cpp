// libFuzzer target: the T-spline file reader (tspline.json: header, T-mesh,
// knot vectors, control points), and an evaluation of the map it returns.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "tspline/io/tspline_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expect_toolkit_errors_only([&] {
    const tspline::io::LoadedTSpline t = tspline::io::parse_tspline_file(text, "fuzz.json");
    (void)t.map.point(Eigen::Vector2d(0.3, 0.7));
  });
  return 0;
}
