#pragma once
// The subcommands of the `tspline` program, one file each (cmd_*.cpp).
//
// Each add_*_commands() registers its subcommands on `app`. When one of them is
// parsed, its callback stores the work to do in `action`; main() then runs
// `action()` inside its usual error handling (InputError -> exit 1, IoError ->
// exit 2, anything else -> exit 4), and returns the exit code it yields.
#include <CLI/CLI.hpp>
#include <functional>

namespace tspline_app {

/// The work of the parsed subcommand; returns the process exit code.
using CommandAction = std::function<int()>;

/// `tspline param`: the parameterization of a domain and its output folder (cmd_param.cpp).
void add_param_command(CLI::App& app, CommandAction& action);

/// `tspline eval` and `tspline info`: evaluate / describe a T-spline file
/// (docs/tspline_format.md).
void add_tspline_file_commands(CLI::App& app, CommandAction& action);

/// `tspline poisson`: isogeometric Poisson solve with adaptive or uniform
/// refinement on the domain of a T-spline file (cmd_poisson.cpp).
void add_poisson_command(CLI::App& app, CommandAction& action);

/// `tspline check`: certify det J > 0 on every Bezier element of a T-spline
/// file (cmd_check.cpp); exit 3 if the map is not certified valid.
void add_check_command(CLI::App& app, CommandAction& action);

/// `tspline export --bezier`: Bezier extraction export (cmd_export.cpp).
void add_export_command(CLI::App& app, CommandAction& action);

/// `tspline render`: PNG pictures of the outputs of param and poisson (cmd_render.cpp).
void add_render_command(CLI::App& app, CommandAction& action);

}  // namespace tspline_app
