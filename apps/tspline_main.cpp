// tspline: command-line front end of libtspline. Thin by design: it parses
// options, calls the library, prints progress, and maps errors to exit codes.
// Exit codes (apps/exit_codes.h, shared with meshopt):
//   exit 0  success
//   exit 1  invalid input (polygon, corners, options)
//   exit 2  file could not be read or written
//   exit 3  the run finished but the map is not valid (det J <= 0 somewhere,
//           or det J > 0 not certified on every element; `tspline check`),
//           or a numerical step failed (e.g. a singular interpolation system)
//   exit 4  unexpected internal error
//   exit 130 interrupted (Ctrl-C): stopped before writing any output
#include <CLI/CLI.hpp>
#include <iostream>

#include "commands.h"
#include "exit_codes.h"
#include "param_options.h"
#include "interrupt.h"

// LeakSanitizer suppressions of the program (third-party libraries only): apps/petsc_session.cpp.

int main(int argc, char** argv) {
  CLI::App app{"tspline: T-spline parameterization of 2D domains for isogeometric analysis"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "tspline " TSPLINE_VERSION);

  tspline_app::CommandAction command;  // set by the subcommand parsed (commands.h)
  tspline_app::add_param_command(app, command);
  tspline_app::add_tspline_file_commands(app, command);
  tspline_app::add_check_command(app, command);
  tspline_app::add_poisson_command(app, command);
  tspline_app::add_render_command(app, command);
  tspline_app::add_export_command(app, command);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "tspline: error: " << e.what() << " (see --help)" << std::endl;
    return 1;
  }
  tspline_app::install_interrupt_handlers();
  try {
    if (command) return command();
  } catch (...) {
    return tspline_app::report_current_exception("tspline", [](std::string message) {
      return tspline_app::with_option_names(std::move(message), tspline_app::Spelling::Cli);
    });
  }
  return 0;
}
