// Automatic quad layouts (layout/quad_layout.h) of domains: patches, nodes,
// valences, straight-sided quality and time. Usage: bench_layout FILE...
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "tspline/boundary/domain.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/layout/quad_layout.h"
#include "toolkit/timing.h"

int main(int argc, char** argv) {
  std::cout << std::setprecision(4);
  for (int i = 1; i < argc; ++i) {
    try {
      const tspline::io::DomainInput in = tspline::io::read_domain(argv[i]);
      const tspline::Domain d = tspline::validate_domain({in.outer, in.holes});
      const auto t0 = std::chrono::steady_clock::now();
      const tspline::QuadLayout L = tspline::build_quad_layout(d);
      const double s = toolkit::seconds_since(t0);
      std::cout << argv[i] << ": holes " << d.holes.size() << ", " << L.explanation() << ", repairs "
                << L.stats.repair_rounds << ", " << s << " s" << std::endl;
      // Patch corners of (nearly) 180 degrees or more: no map can be valid there.
      for (std::size_t p = 0; p < L.layout.patches.size(); ++p) {
        const auto& P = L.layout.patches[p];
        const auto& v = P.polygon.vertices;
        const std::size_t n = v.size();
        for (int k = 0; k < 4; ++k) {
          const std::size_t c = P.corners[k];
          const Eigen::Vector2d a = v[(c + n - 1) % n] - v[c], b = v[(c + 1) % n] - v[c];
          double t = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
          if (t < 0) t += 2 * M_PI;
          t = 2 * M_PI - t;
          if (t * 180 / M_PI > 170 || t * 180 / M_PI < 15)
            std::cout << "  patch " << p << " corner " << k << " at (" << v[c].x() << ", " << v[c].y() << ") angle "
                      << t * 180 / M_PI << ", side cuts " << P.side_cut[k] << " " << P.side_cut[(k + 3) % 4]
                      << std::endl;
        }
      }
    } catch (const std::exception& e) {
      std::cout << argv[i] << ": error: " << e.what() << std::endl;
    }
  }
}
