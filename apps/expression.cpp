#include "expression.h"

#include <muParser.h>

#include <numbers>
#include <utility>

#include "toolkit/errors.h"

namespace tspline_app {

struct Expression::Impl {
  // The parser keeps the addresses of x and y: Impl lives on the heap and is
  // never copied or moved.
  double x = 0.0, y = 0.0, z = 0.0;
  mu::Parser parser;
};

Expression::Expression(std::string option, std::string text, bool three_d)
    : option_(std::move(option)), text_(std::move(text)), impl_(std::make_unique<Impl>()) {
  try {
    impl_->parser.DefineVar("x", &impl_->x);
    impl_->parser.DefineVar("y", &impl_->y);
    if (three_d) impl_->parser.DefineVar("z", &impl_->z);
    impl_->parser.DefineConst("pi", std::numbers::pi);
    impl_->parser.SetExpr(text_);
    // muParser parses lazily, on the first evaluation: force it now so that a
    // syntax error is reported before any work (the value itself is not checked).
    int results = 0;
    impl_->parser.Eval(results);
    if (results != 1)
      throw toolkit::InputError(option_ + ": cannot parse '" + text_ + "': it gives " +
                                std::to_string(results) +
                                " comma-separated values, expected one expression in x and y" + (three_d ? " and z" : ""));
  } catch (const mu::Parser::exception_type& e) {
    throw toolkit::InputError(option_ + ": cannot parse '" + text_ + "': " + e.GetMsg());
  }
}

Expression::~Expression() = default;

double Expression::operator()(double x, double y, double z) const {
  impl_->x = x;
  impl_->y = y;
  impl_->z = z;
  try {
    return impl_->parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw toolkit::InputError(option_ + ": cannot evaluate '" + text_ + "' at x = " + std::to_string(x) +
                              ", y = " + std::to_string(y) + ", z = " + std::to_string(z) + ": " + e.GetMsg());
  }
}

std::function<double(double, double)> make_field(const std::string& option, const std::string& text) {
  auto e = std::make_shared<const Expression>(option, text);
  return [e](double x, double y) { return (*e)(x, y); };
}

}  // namespace tspline_app
