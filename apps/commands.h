#pragma once
// The subcommands of the `tspline` program, one file each (cmd_*.cpp).
//
// Each add_*_commands() registers its subcommands on `app`. When one of them is
// parsed, its callback stores the work to do in `action`; main() then runs
// `action()` inside its usual error handling (InputError -> exit 1, IoError ->
// exit 2, anything else -> exit 4), and returns the exit code it yields.
#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>
#include <utility>

namespace tspline_app {

/// The work of the parsed subcommand; returns the process exit code.
using CommandAction = std::function<int()>;

/// A registered subcommand and the struct its options write into, shared with
/// its callback (which runs after parsing).
template <class Args>
struct Subcommand {
  CLI::App* cmd;
  std::shared_ptr<Args> args;
};

/// Registers subcommand `name` on `app` with a fresh `Args` for its options.
/// (Name its members, not a structured binding of it: clang before 16, e.g.
/// Debian 12's clang 14, cannot capture a structured binding in a lambda.)
template <class Args>
Subcommand<Args> add_subcommand(CLI::App& app, std::string name, std::string description) {
  return {app.add_subcommand(std::move(name), std::move(description)), std::make_shared<Args>()};
}

/// When `cmd` is parsed, its work becomes `run(*args)`.
template <class Args, class Run>
void run_when_parsed(CLI::App* cmd, std::shared_ptr<Args> args, CommandAction& action, Run run) {
  cmd->callback([args, run, &action] { action = [args, run] { return run(*args); }; });
}

/// The positional TSPLINE argument (a required file) of the commands that read a T-spline file.
inline CLI::Option* add_tspline_file_argument(
    CLI::App& cmd, std::string& file,
    const std::string& help = "T-spline file (tspline.json, see docs/tspline_format.md)") {
  return cmd.add_option("TSPLINE", file, help)->type_name("FILE")->required();
}

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
