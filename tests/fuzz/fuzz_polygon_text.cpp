// libFuzzer target: the text polygon reader, then the cleaning and the exact
// validation every polygon goes through (tspline param's first steps). Any
// exception other than the toolkit's own, and any sanitizer report, is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/boundary/polygon_validation.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expect_toolkit_errors_only([&] {
    tspline::Polygon p = tspline::io::parse_polygon(text, "fuzz.txt");
    tspline::validate_polygon(tspline::clean_polygon(std::move(p)).polygon);
  });
  return 0;
}
