// libFuzzer target: the front half of `tspline param` (cleaning, validation,
// automatic or given corners, adapted T-mesh, Coons start, optimization and
// repair) on small text polygons, with small budgets so that each input runs
// in milliseconds. A budget that is exceeded must be an InputError, never a
// hang, a crash or an internal error.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/parameterization.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 2048) return 0;  // small polygons only
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expect_toolkit_errors_only([&] {
    const tspline::Polygon p = tspline::io::parse_polygon(text, "fuzz.txt");
    if (p.vertices.size() > 48) return;
    tspline::ParameterizationOptions opt;
    opt.initial_level = 1;
    opt.max_level = 7;
    opt.max_cells = 1500;
    opt.corner_trials = 1;
    opt.max_repair_rounds = 2;
    opt.smoothing.max_sweeps = 30;
    const tspline::FrontResult r = tspline::run_front(p, opt);
    if (r.mesh.num_cells() > opt.max_cells) fuzz::fail("the front half exceeded max_cells");
  });
  return 0;
}
