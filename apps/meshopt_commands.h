#pragma once
// Subcommands of the meshopt program other than smooth (which lives in meshopt_main.cpp).
#include <string>

namespace meshopt_app {

struct RemeshArgs {
  std::string model, out, mesh, vtu, report;
  double length = 0.0;       ///< 0: derived from max_deviation (see cmd_remesh.cpp)
  double anisotropy = -1.0;  ///< < 0: the default (see cmd_remesh.cpp)
  double max_deviation = 0.0;  ///< 0: no cap on the chordal deviation
  double feature_angle = 30.0;
  double min_angle = 20.0;
  int rounds = 3;
  bool quiet = false, json = false;
};

/// meshopt remesh: curvature-adapted anisotropic remeshing (Dassi et al. 2014). Exit code.
int run_remesh(const RemeshArgs& args);

}  // namespace meshopt_app
