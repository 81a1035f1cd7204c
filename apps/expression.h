#pragma once
// Scalar fields given as expressions in x and y on the command line, parsed
// with muParser (https://beltoforion.de/en/muparser/).
#include <functional>
#include <memory>
#include <string>

namespace tspline_app {

/// An expression in the variables x and y (and z, for fields in 3D). It is parsed once, in the
/// constructor; each evaluation binds x and y to the given doubles and runs the
/// parser's bytecode. Besides muParser's built-ins (+ - * / ^, sin, cos, tan,
/// asin, acos, atan, sinh, cosh, tanh, exp, log = ln, log10, log2, sqrt, abs,
/// sign, min, max, the constants _pi and _e) the constant `pi` is defined.
///
/// Not thread-safe: one Expression (one parser) per field, used by one thread.
class Expression {
 public:
  /// \param option names the command-line option in error messages ("--f").
  /// \throw tspline::InputError "--f: cannot parse 'TEXT': <muParser's message>"
  /// if the text is not a single expression in x and y.
  /// With `three_d`, the variable z is defined as well.
  Expression(std::string option, std::string text, bool three_d = false);
  ~Expression();
  Expression(const Expression&) = delete;
  Expression& operator=(const Expression&) = delete;

  /// The value at (x, y); may be NaN or infinite (sqrt(-1), 1/0): callers check.
  /// \throw tspline::InputError if muParser reports an evaluation error.
  double operator()(double x, double y) const { return (*this)(x, y, 0.0); }
  /// The value at (x, y, z) (z is ignored unless constructed with three_d).
  double operator()(double x, double y, double z) const;
  const std::string& text() const { return text_; }

 private:
  struct Impl;
  std::string option_, text_;
  std::unique_ptr<Impl> impl_;
};

/// A scalar field (tspline::ScalarField) evaluating `text` (owns its own parser, shared by the copies of
/// the returned std::function). \throw tspline::InputError as Expression.
std::function<double(double, double)> make_field(const std::string& option, const std::string& text);

}  // namespace tspline_app
