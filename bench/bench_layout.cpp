// Automatic quad layouts (layout/quad_layout.h) of domains: patches, nodes,
// valences, straight-sided quality and time.
// Usage: bench_layout [--blunt-tips DEG] FILE...
// --blunt-tips cuts sharp tips as `tspline param` does by default (17.5), with
// the default boundary tolerance (1e-5 relative); without it the rings are taken
// as they are.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <string>

#include "tspline/boundary/domain.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/layout/quad_layout.h"
#include "toolkit/timing.h"

int main(int argc, char** argv) {
  std::cout << std::setprecision(4);
  double blunt_degrees = 0.0;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--blunt-tips" && i + 1 < argc) {
      blunt_degrees = std::stod(argv[++i]);
      continue;
    }
    try {
      const tspline::io::DomainInput in = tspline::io::read_domain(argv[i]);
      tspline::DomainCleaningOptions how;
      if (blunt_degrees > 0.0) {
        // As apps/param_session.cpp does with the default tolerance.
        constexpr double relative = 1e-5;
        const double width = tspline::needle_width_for_ring(in.outer, std::nullopt, relative);
        how.needle_width = width;
        how.crossing_repair_area = std::isfinite(width) ? width * width / relative : 0.0;
        how.blunt_tips_below_degrees = blunt_degrees;
      }
      const tspline::Domain d = tspline::validate_domain({in.outer, in.holes}, how);
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
