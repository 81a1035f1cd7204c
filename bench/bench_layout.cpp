// Automatic quad layouts (layout/quad_layout.h) of domains: patches, nodes,
// valences, straight-sided quality and time. Usage: bench_layout FILE...
#include <chrono>
#include <iomanip>
#include <iostream>

#include "tspline/boundary/domain.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/layout/quad_layout.h"

int main(int argc, char** argv) {
  std::cout << std::setprecision(4);
  for (int i = 1; i < argc; ++i) {
    try {
      const tspline::io::DomainInput in = tspline::io::read_domain(argv[i]);
      const tspline::Domain d = tspline::validate_domain({in.outer, in.holes});
      const auto t0 = std::chrono::steady_clock::now();
      const tspline::QuadLayout L = tspline::build_quad_layout(d);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::cout << argv[i] << ": holes " << d.holes.size() << ", " << L.explanation() << ", repairs "
                << L.stats.repair_rounds << ", " << s << " s" << std::endl;
    } catch (const std::exception& e) {
      std::cout << argv[i] << ": error: " << e.what() << std::endl;
    }
  }
}
