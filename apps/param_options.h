#pragma once
// The options of `tspline param` and of the Python module's
// tspline.parameterize in ONE table: each option's name, help, default, value
// parsing and validation, and the settings fields it sets. The program
// registers one CLI11 option per entry (param_options_cli.h); the Python
// module turns each keyword into the same text and calls the same setter, so
// that the two front ends cannot drift. Python spells a name with '_' for '-'
// (init-level -> init_level).
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "toolkit/io/vtu_writer.h"
#include "tspline/io/gis_reader.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/pipeline/domain_parameterization.h"
#include "tspline/pipeline/parameterization.h"

namespace tspline_app {

/// Everything `tspline param` takes besides the domain, the output folder and
/// how it prints.
struct ParamSettings {
  tspline::ParameterizationOptions opt;
  tspline::AdaptiveOptions adaptive;
  tspline::io::DomainReadOptions domain;
  /// Layout choice; `choice.cuts` is filled from `cuts_file` when the run starts.
  tspline::DomainParameterizationOptions choice;
  std::string cuts_file;  ///< polylines, one cut per blank-line-separated block ("" for none)
  /// Holes that cross themselves become their convex hulls (DomainCleaningOptions).
  bool repair_crossing_holes = false;
  /// Tips of the domain sharper than this (degrees) are cut off within the
  /// boundary tolerance (DomainCleaningOptions::blunt_tips_below_degrees): 17.5
  /// degrees, where sin(theta) = 0.3, the scaled Jacobian a good map keeps.
  double blunt_tips_degrees = 17.5;
  /// A previous map (tspline.json) of the same boundary before it moved: warm start ("" for none).
  std::string from_file;
  int samples = 4;        ///< surface.vtu: k x k sub-quads per cell
  /// The .vtu files' compression: LZ4 by default (zlib takes about five times
  /// its CPU for files about a quarter smaller; bench/README.md, "LZ4 files").
  toolkit::io::VtuCompression vtu_compression = toolkit::io::VtuCompression::LZ4;
};

/// How an option's value is written (on the command line and in Python).
enum class OptionKind {
  Flag,     ///< no value (Python: a bool; False leaves the default)
  Integer,  ///< a signed integer (CLI11 "INT")
  Count,    ///< a non-negative integer (CLI11 "UINT")
  Real,     ///< a finite floating-point number (CLI11 "FLOAT")
  Text,     ///< text: a name, a path, a list (CLI11 "TEXT")
};

struct ParamOption {
  std::string name;  ///< command-line spelling without the dashes: "init-level"
  OptionKind kind = OptionKind::Text;
  std::string help;
  /// The accepted values, if only some are (e.g. --layout auto|single|quad).
  std::vector<std::string> choices;
  /// The accepted range of a number, inclusive, if limited here (most ranges
  /// are checked by the library when the run starts: validate_options).
  std::optional<std::pair<double, double>> range;
  /// Show the default in the help (an option without one is "unset" by default).
  bool show_default = true;
  /// Parses `text` (for a flag: "true"), validates it against `choices` and
  /// `range`, and sets the settings' fields. \throw tspline::InputError with a
  /// message that does not name the option (the caller prefixes its spelling).
  std::function<void(ParamSettings&, const std::string& text)> set;
  /// The fields this option sets, as JSON (what a test compares between the
  /// two front ends) and, for the help, the default (settings_default_text).
  std::function<nlohmann::json(const ParamSettings&)> get;

  /// The library's names of the fields it sets, as the libraries' messages
  /// name them in backquotes ("`max_cells` must be >= 1"): with_option_names
  /// turns them into this option's spelling.
  std::vector<std::string> fields;

  /// The Python keyword: '-' replaced by '_'.
  std::string python_name() const;
  /// The default as the help shows it ("" without show_default).
  std::string default_text() const;
  /// set() with errors prefixed by `spelling` ("--init-level" or "init_level"):
  /// "init_level: 'x' is not an integer".
  void apply(ParamSettings& settings, const std::string& text, const std::string& spelling) const;
};

/// The table, in the order of the help.
const std::vector<ParamOption>& param_options();

/// The entry with this CLI or Python name (`init-level` or `init_level`), or null.
const ParamOption* find_param_option(std::string_view name);

/// Every settings field that some option sets, by option name (the `get` of
/// each entry): equal for two settings iff every option maps to the same values.
nlohmann::json settings_json(const ParamSettings& settings);

/// How a front end spells its options.
enum class Spelling { Cli, Python };

/// The message with every backquoted library field name that an option sets
/// ("`initial_level`", "`certification.max_depth`") replaced by that option's
/// name in the front end's spelling (--init-level, init_level); also the
/// `step`, `view` and `problem` of the render and poisson commands. Other
/// backquoted names (fields only a C++ caller sets) are left as they are.
std::string with_option_names(std::string message, Spelling spelling);

/// "0,5,10,15" -> the four corner indices. \throw tspline::InputError.
std::array<long long, 4> parse_corners(const std::string& text);

}  // namespace tspline_app
