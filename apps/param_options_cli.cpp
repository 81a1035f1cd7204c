#include "param_options_cli.h"

#include <algorithm>

#include "tspline/errors.h"

namespace tspline_app {
namespace {

const char* type_name(OptionKind kind) {
  switch (kind) {
    case OptionKind::Integer:
      return "INT";
    case OptionKind::Count:
      return "UINT";
    case OptionKind::Real:
      return "FLOAT";
    case OptionKind::Flag:
    case OptionKind::Text:
      break;
  }
  return "TEXT";
}

}  // namespace

void add_param_options(CLI::App& cmd, const std::shared_ptr<ParamSettings>& settings) {
  for (const ParamOption& o : param_options()) {
    const std::string flag = "--" + o.name;
    if (o.kind == OptionKind::Flag) {
      cmd.add_flag_callback(
          flag, [&o, settings, flag] { o.apply(*settings, "true", flag); }, o.help);
      continue;
    }
    CLI::Option* opt = cmd.add_option_function<std::string>(
        flag,
        [&o, settings, flag](const std::string& text) {
          try {
            o.apply(*settings, text, flag);
          } catch (const tspline::InputError& e) {
            throw CLI::ValidationError(e.what());
          }
        },
        o.help);
    opt->type_name(type_name(o.kind));
    if (!o.choices.empty()) opt->check(CLI::IsMember(o.choices));
    if (o.range && o.kind == OptionKind::Real) opt->check(CLI::Range(o.range->first, o.range->second));
    if (o.range && o.kind != OptionKind::Real)
      opt->check(CLI::Range(static_cast<long long>(o.range->first), static_cast<long long>(o.range->second)));
    if (o.show_default) opt->default_str(o.default_text());
  }
}

ParamSettings parse_param_arguments(const std::vector<std::string>& args) {
  CLI::App app;
  CLI::App* cmd = app.add_subcommand("param");
  auto settings = std::make_shared<ParamSettings>();
  std::string input, out;
  cmd->add_option("DOMAIN", input)->required();
  cmd->add_option("--out", out)->required();
  add_param_options(*cmd, settings);
  std::vector<std::string> argv{"param"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::reverse(argv.begin(), argv.end());  // CLI11 takes the arguments last first
  try {
    app.parse(argv);
  } catch (const CLI::ParseError& e) {
    throw tspline::InputError(e.what());
  }
  return *settings;
}

}  // namespace tspline_app
