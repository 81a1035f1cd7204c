#include "param_options.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

#include "tspline/errors.h"
#include "vtu_compression_option.h"

namespace tspline_app {
namespace {

using nlohmann::json;
using tspline::InputError;

// ------------------------------------------------------------ value parsing

/// The whole text as a number of type T (an optional leading '+' allowed).
template <class T>
std::optional<T> whole_number(const std::string& text) {
  const char* b = text.data();
  const char* e = b + text.size();
  if (b != e && *b == '+') ++b;
  T v{};
  const auto [end, ec] = std::from_chars(b, e, v);
  if (b == e || ec != std::errc() || end != e) return std::nullopt;
  return v;
}

long long parse_integer(const std::string& text) {
  const auto v = whole_number<long long>(text);
  if (!v) throw InputError("'" + text + "' is not an integer");
  return *v;
}

int parse_int(const std::string& text) {
  const long long v = parse_integer(text);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    throw InputError(text + " is out of the range of an integer");
  return static_cast<int>(v);
}

std::size_t parse_count(const std::string& text) {
  const auto v = whole_number<unsigned long long>(text);
  if (!v) throw InputError("'" + text + "' is not a non-negative integer");
  return static_cast<std::size_t>(*v);
}

double parse_real(const std::string& text) {
  const auto v = whole_number<double>(text);
  if (!v) throw InputError("'" + text + "' is not a number");
  if (!std::isfinite(*v)) throw InputError("'" + text + "' is not a finite number");
  return *v;
}

std::string number_text(double v) {
  std::ostringstream s;  // as CLI11 shows defaults
  s << v;
  return s.str();
}

void check_choice(const std::vector<std::string>& choices, const std::string& text) {
  for (const std::string& c : choices)
    if (c == text) return;
  std::string list;
  for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + c;
  throw InputError("'" + text + "' is not one of " + list);
}

void check_range(const std::pair<double, double>& range, double v) {
  if (!(v >= range.first && v <= range.second))
    throw InputError(number_text(v) + " is not in [" + number_text(range.first) + ", " +
                     number_text(range.second) + "]");
}

// ------------------------------------------------------------ table builders

using Setter = std::function<void(ParamSettings&, const std::string&)>;
using Getter = std::function<json(const ParamSettings&)>;

ParamOption option(std::string name, OptionKind kind, std::string help, Setter set, Getter get) {
  ParamOption o;
  o.name = std::move(name);
  o.kind = kind;
  o.help = std::move(help);
  o.set = std::move(set);
  o.get = std::move(get);
  return o;
}

/// A number option on one field; `field(s)` is that field of s (const or not).
template <class T, class Field>
ParamOption number(std::string name, std::string help, Field field) {
  constexpr OptionKind kind = std::is_floating_point_v<T>      ? OptionKind::Real
                              : std::is_same_v<T, std::size_t> ? OptionKind::Count
                                                               : OptionKind::Integer;
  auto set = [field](ParamSettings& s, const std::string& text) {
    if constexpr (kind == OptionKind::Real)
      field(s) = parse_real(text);
    else if constexpr (kind == OptionKind::Count)
      field(s) = parse_count(text);
    else
      field(s) = parse_int(text);
  };
  return option(std::move(name), kind, std::move(help), set,
                [field](const ParamSettings& s) { return json(field(s)); });
}

/// The setter with the entry's choices and range checked first.
Setter validated(const ParamOption& o) {
  return [choices = o.choices, range = o.range, set = o.set](ParamSettings& s, const std::string& text) {
    if (!choices.empty()) check_choice(choices, text);
    if (range) check_range(*range, parse_real(text));
    set(s, text);
  };
}

std::vector<ParamOption> make_table() {
  std::vector<ParamOption> t;
  t.push_back(option(
      "layout", OptionKind::Text,
      "auto: one patch where a first try is certified and good over the whole map (scaled Jacobian >= 0.3, "
      "J_r >= "
      "0.1), an automatic quad layout otherwise and always for domains with holes; single: one patch (no "
      "holes); "
      "quad: the automatic quad layout",
      [](ParamSettings& s, const std::string& v) { s.choice.layout = tspline::parse_layout_mode(v); },
      [](const ParamSettings& s) { return json(tspline::layout_mode_name(s.choice.layout)); }));
  t.back().choices = {"auto", "single", "quad"};
  t.push_back(option(
      "cuts", OptionKind::Text,
      "The layout given by hand: cuts into four-sided patches as polylines ('x y' per line, cuts separated "
      "by blank "
      "lines; ends on rings or at ends of other cuts); default: --layout",
      [](ParamSettings& s, const std::string& v) { s.cuts_file = v; },
      [](const ParamSettings& s) { return json(s.cuts_file); }));
  t.back().show_default = false;
  t.push_back(option(
      "from", OptionKind::Text,
      "A previous map (its tspline.json) of this boundary before it moved, vertex i moved to vertex i: the new "
      "map keeps its T-mesh, knots and corners, starts from it moved with the boundary and is untangled, "
      "improved and refined only where it needs it (moving domains, shape optimization)",
      [](ParamSettings& s, const std::string& v) { s.from_file = v; },
      [](const ParamSettings& s) { return json(s.from_file); }));
  t.back().show_default = false;
  t.push_back(option(
      "repair-crossings", OptionKind::Flag,
      "Replace every hole whose ring crosses itself (a bow-tie islet of quantized data) by its convex hull, "
      "with a note giving both areas; by default only a crossing islet whose hull is smaller than the boundary "
      "tolerance's area is (it lies below the tolerance), a larger one is an input error naming its edges",
      [](ParamSettings& s, const std::string&) { s.repair_crossing_holes = true; },
      [](const ParamSettings& s) { return json(s.repair_crossing_holes); }));
  t.push_back(number<double>(
      "blunt-tips",
      "Cut off every tip of the domain sharper than this many degrees (a patch corner of angle theta has "
      "scaled Jacobian sin(theta) in any map) by a chord removing at most the boundary tolerance's area, "
      "with a note per tip; 0 keeps every tip (and --from always does)",
      [](auto& s) -> auto& { return s.blunt_tips_degrees; }));
  t.back().range = {{0.0, 90.0}};
  t.push_back(option(
      "corners", OptionKind::Text,
      "Four vertex indices i,j,k,l (0-based, the file's own numbering, in cyclic file order) mapped to "
      "(0,0),(1,0),(1,1),(0,1); default: automatic choice explained in report.json",
      [](ParamSettings& s, const std::string& v) { s.opt.corners = parse_corners(v); },
      [](const ParamSettings& s) { return s.opt.corners ? json(*s.opt.corners) : json(); }));
  t.back().show_default = false;
  t.push_back(number<int>(
      "corner-trials",
      "Automatic corners: run this many of the best choices and keep the one with the fewest "
      "inverted cells, then the best min + mean quality (1: no trials)",
      [](auto& s) -> auto& { return s.opt.corner_trials; }));
  t.push_back(option(
      "tol", OptionKind::Real,
      "Boundary tolerance epsilon as an absolute AREA (units^2): a boundary cell is refined while a polygon "
      "vertex forms with its edge a triangle larger than epsilon (Brovka 2013 Sect. 3); each patch of a "
      "layout takes the smaller of epsilon and --tol-rel times its own squared diagonal",
      [](ParamSettings& s, const std::string& v) { s.opt.tolerance_absolute = parse_real(v); },
      [](const ParamSettings& s) {
        return s.opt.tolerance_absolute ? json(*s.opt.tolerance_absolute) : json();
      }));
  t.back().show_default = false;
  t.push_back(number<double>(
      "tol-rel",
      "Boundary tolerance relative to the squared bounding-box diagonal, used when --tol is "
      "not given",
      [](auto& s) -> auto& { return s.opt.tolerance_relative; }));
  t.push_back(option(
      "init-level", OptionKind::Integer,
      "Initial uniform level L in [0, 10]: 2^L x 2^L cells (patches of a quad layout: 2 unless given; at 0 the boundary must refine the cell: a map needs 2 x 2 cells)",
      [](ParamSettings& s, const std::string& v) {
        s.opt.initial_level = parse_int(v);
        s.choice.patch_initial_level = s.opt.initial_level;  // given: the patches' too
      },
      [](const ParamSettings& s) {
        return json{{"initial_level", s.opt.initial_level},
                    {"patch_initial_level",
                     s.choice.patch_initial_level ? json(*s.choice.patch_initial_level) : json()}};
      }));
  t.push_back(number<int>(
      "max-level", "Maximum refinement level of any cell", [](auto& s) -> auto& { return s.opt.max_level; }));
  t.push_back(number<int>(
      "max-sweeps", "Maximum Gauss-Seidel sweeps of the optimization",
      [](auto& s) -> auto& { return s.opt.smoothing.max_sweeps; }));
  t.push_back(number<double>(
      "omega", "Over-relaxation factor in [1, 2) of the node updates (1: plain Gauss-Seidel)",
      [](auto& s) -> auto& { return s.opt.smoothing.over_relaxation; }));
  t.push_back(number<double>(
      "sweep-tol", "Stop when the largest node move relative to its local edge length is below this",
      [](auto& s) -> auto& { return s.opt.smoothing.relative_displacement_tolerance; }));
  t.push_back(option(
      "polygon", OptionKind::Count,
      "GIS file (or GeoJSON) with several polygons (in the layer or the --feature): which one (0-based, file "
      "order); default the largest",
      [](ParamSettings& s, const std::string& v) { s.domain.polygon_index = parse_count(v); },
      [](const ParamSettings& s) {
        return s.domain.polygon_index ? json(*s.domain.polygon_index) : json();
      }));
  t.back().show_default = false;
  t.push_back(option(
      "layer", OptionKind::Text,
      "GIS file: layer name or 0-based index; default the first layer with polygons",
      [](ParamSettings& s, const std::string& v) { s.domain.layer = v; },
      [](const ParamSettings& s) { return s.domain.layer ? json(*s.domain.layer) : json(); }));
  t.back().show_default = false;
  t.push_back(option(
      "feature", OptionKind::Count, "GIS file: only this feature (0-based, layer order)",
      [](ParamSettings& s, const std::string& v) { s.domain.feature = parse_count(v); },
      [](const ParamSettings& s) { return s.domain.feature ? json(*s.domain.feature) : json(); }));
  t.back().show_default = false;
  t.push_back(option(
      "planar", OptionKind::Flag,
      "Keep the coordinates as they are (no projection of longitude/latitude to metres)",
      [](ParamSettings& s, const std::string&) { s.domain.planar = true; },
      [](const ParamSettings& s) { return json(s.domain.planar); }));
  t.push_back(number<double>(
      "min-jacobian",
      "delta of Sect. 6.2: refine the cells where the mean ratio Jacobian J_r = 2 det J / "
      "|J|^2 is below it at some of the 4x4 Gauss points",
      [](auto& s) -> auto& { return s.adaptive.min_jacobian; }));
  t.push_back(number<int>(
      "max-adapt", "Adaptive refinement rounds at most",
      [](auto& s) -> auto& { return s.adaptive.max_adapt; }));
  t.push_back(option(
      "max-cells", OptionKind::Count,
      "The T-mesh never goes beyond this many cells (boundary refinement, repair, adaptive refinement); a "
      "polygon "
      "that needs more stops with a message",
      [](ParamSettings& s, const std::string& v) {
        s.opt.max_cells = parse_count(v);  // one budget for the front half and the adaptive loop
      },
      [](const ParamSettings& s) { return json(s.opt.max_cells); }));
  t.push_back(option(
      "no-control-point-optimization", OptionKind::Flag,
      "Keep the interpolating map of the T-mesh (by default all interior control points are untangled and "
      "smoothed globally until det J > 0 is certified)",
      [](ParamSettings& s, const std::string&) { s.adaptive.optimize_control_points = false; },
      [](const ParamSettings& s) { return json(!s.adaptive.optimize_control_points); }));
  t.push_back(option(
      "optimizer", OptionKind::Text,
      "Minimizer of the control-point untangling and smoothing: 'lbfgs' (L-BFGS, curvature kept across the eps "
      "stages) or 'newton' (projected Newton, Cholesky or conjugate gradients: fewer iterations and a higher min "
      "J_r, each iteration a Hessian assembly; slower on the benchmarks)",
      [](ParamSettings& s, const std::string& v) {
        s.adaptive.untangling.optimizer =
            v == "lbfgs" ? tspline::MapOptimizer::LBFGS : tspline::MapOptimizer::Newton;
      },
      [](const ParamSettings& s) {
        return json(s.adaptive.untangling.optimizer == tspline::MapOptimizer::LBFGS ? "lbfgs" : "newton");
      }));
  t.back().choices = {"newton", "lbfgs"};
  t.push_back(number<int>(
      "cert-depth",
      "Certification of det J > 0 on every Bezier element: de Casteljau subdivision levels at "
      "most (an element still undecided there is refined like one with J_r below "
      "--min-jacobian)",
      [](auto& s) -> auto& { return s.adaptive.certification.max_depth; }));
  t.back().range = {{0.0, 20.0}};
  t.push_back(number<int>(
      "samples", "surface.vtu: k x k sub-quads per T-mesh cell", [](auto& s) -> auto& { return s.samples; }));
  t.back().range = {{1.0, 64.0}};
  t.push_back(option(
      "vtu-compression", OptionKind::Text, kVtuCompressionHelp,
      [](ParamSettings& s, const std::string& v) {
        s.vtu_compression = toolkit::io::parse_vtu_compression(v);
      },
      [](const ParamSettings& s) {
        return json(std::string(toolkit::io::vtu_compression_name(s.vtu_compression)));
      }));
  t.back().choices = {"lz4", "zlib", "none"};
  const std::vector<std::pair<const char*, std::vector<std::string>>> fields = {
      {"layout", {"layout"}},
      {"cuts", {"cuts"}},
      {"corners", {"corners"}},
      {"corner-trials", {"corner_trials"}},
      {"tol", {"tolerance_absolute"}},
      {"tol-rel", {"tolerance_relative"}},
      {"init-level", {"initial_level"}},
      {"max-level", {"max_level"}},
      {"max-sweeps", {"smoothing.max_sweeps"}},
      {"omega", {"smoothing.over_relaxation"}},
      {"sweep-tol", {"smoothing.relative_displacement_tolerance"}},
      {"polygon", {"polygon_index"}},
      {"layer", {"layer"}},
      {"feature", {"feature"}},
      {"planar", {"planar"}},
      {"min-jacobian", {"min_jacobian"}},
      {"max-adapt", {"max_adapt"}},
      {"max-cells", {"max_cells"}},
      {"repair-crossings", {"repair_crossing_holes"}},
      {"blunt-tips", {"blunt_tips_below_degrees"}},
      {"cert-depth", {"certification.max_depth"}},
      {"optimizer", {"untangling.optimizer"}},
      {"samples", {"samples"}},
      {"vtu-compression", {"vtu_compression"}},
  };
  for (const auto& [name, names] : fields)
    for (ParamOption& o : t)
      if (o.name == name) o.fields = names;
  for (ParamOption& o : t) o.set = validated(o);  // choices and range before anything is set
  return t;
}

}  // namespace

std::string with_option_names(std::string message, Spelling spelling) {
  std::vector<std::pair<std::string, std::string>> names;  // field -> spelling
  for (const ParamOption& o : param_options())
    for (const std::string& f : o.fields)
      names.emplace_back(f, spelling == Spelling::Cli ? "--" + o.name : o.python_name());
  for (const char* other : {"step", "view", "problem"})
    names.emplace_back(other, spelling == Spelling::Cli ? std::string("--") + other : std::string(other));
  for (const auto& [field, spelled] : names) {
    const std::string quoted = "`" + field + "`";
    for (std::size_t at = message.find(quoted); at != std::string::npos; at = message.find(quoted, at + spelled.size()))
      message.replace(at, quoted.size(), spelled);
  }
  return message;
}

std::string ParamOption::python_name() const {
  std::string n = name;
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
}

std::string ParamOption::default_text() const {
  if (!show_default || kind == OptionKind::Flag) return "";
  const json v = get(ParamSettings{});
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_integer()) return v.dump();
  if (v.is_number()) return number_text(v.get<double>());
  if (v.is_object() && !v.empty()) {  // several fields set alike: the first shows the value
    const json& first = v.begin().value();
    return first.is_number_float() ? number_text(first.get<double>()) : first.dump();
  }
  return "";
}

void ParamOption::apply(ParamSettings& settings, const std::string& text, const std::string& spelling) const {
  try {
    set(settings, text);
  } catch (const tspline::InputError& e) {
    throw tspline::InputError(spelling + ": " + e.what());
  }
}

const std::vector<ParamOption>& param_options() {
  static const std::vector<ParamOption> table = make_table();
  return table;
}

const ParamOption* find_param_option(std::string_view name) {
  for (const ParamOption& o : param_options())
    if (o.name == name || o.python_name() == name) return &o;
  return nullptr;
}

json settings_json(const ParamSettings& settings) {
  json out = json::object();
  for (const ParamOption& o : param_options()) out[o.name] = o.get(settings);
  return out;
}

std::array<long long, 4> parse_corners(const std::string& text) {
  std::array<long long, 4> out{};
  std::stringstream ss(text);
  std::string item;
  int n = 0;
  while (std::getline(ss, item, ',')) {
    if (n == 4) throw InputError("expects 4 comma-separated indices, got '" + text + "'");
    const auto v = whole_number<long long>(item);
    if (!v) throw InputError("'" + item + "' is not an integer vertex index");
    out[n++] = *v;
  }
  if (n != 4) throw InputError("expects 4 comma-separated indices, got '" + text + "'");
  return out;
}

}  // namespace tspline_app
