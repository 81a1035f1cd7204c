#pragma once
// The table of param_options.h as CLI11 options of a subcommand: one option
// per entry, `--NAME`, with the entry's help, default, type name, choices and
// range; its value goes through the entry's setter (the same as the Python
// module's), into `settings`.
#include <CLI/CLI.hpp>
#include <memory>
#include <vector>

#include "param_options.h"

namespace tspline_app {

/// Registers every option of param_options() on `cmd`, setting `*settings`
/// when parsed (errors become CLI::ValidationError naming the option).
void add_param_options(CLI::App& cmd, const std::shared_ptr<ParamSettings>& settings);

/// Parses `tspline param` arguments (after "param": DOMAIN, --out and the
/// table's options) into settings, as the program does. For tests that compare
/// the program's and the module's reading of the same options.
/// \throw tspline::InputError for arguments the program rejects.
ParamSettings parse_param_arguments(const std::vector<std::string>& args);

}  // namespace tspline_app
