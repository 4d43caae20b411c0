// Scalar expressions that may depend on `time`. Constants are folded by the
// checker, so a Scalar without an expression is a plain number.
#pragma once
#include <memory>
#include <string>
#include <vector>

namespace sdfc::ir {

struct Expr;
using ExprRef = std::shared_ptr<const Expr>;

struct Expr {
  enum class Op { Const, Time, Add, Sub, Mul, Div, Neg, Call };
  Op op = Op::Const;
  double value = 0;      // Const
  std::string function;  // Call: one of mathFunctionNames()
  std::vector<ExprRef> args;
  // Nodes of the tree written out in full (shared subexpressions count each
  // time), i.e. the size of its GLSL and of a walk over it; saturates.
  double size = 1;
};

// Closed interval, for bounds over all times.
struct Interval {
  double lo = 0, hi = 0;
  bool bounded() const;
};
// The product's range (0 * inf = 0, so an unbounded factor never gives NaN).
Interval multiply(Interval a, Interval b);

struct Scalar {
  double value = 0;  // the value when constant (or at time 0)
  ExprRef expr;      // set when the value depends on time
  bool isConst() const { return !expr; }
  double at(double time) const;
  Interval range() const;  // over every time
  std::string glsl() const;  // time is `frame.cam_forward.w`
  std::string text() const;  // for IR dumps
};

Scalar constant(double v);
Scalar timeScalar();
Scalar unary(char op, const Scalar& a);
Scalar binary(char op, const Scalar& a, const Scalar& b);
// Math functions available in .sdf expressions (sin, cos, ..., clamp, mix).
const std::vector<std::string>& mathFunctionNames();
int mathFunctionArity(const std::string& name);  // -1 if unknown
Scalar callFunction(const std::string& name, const std::vector<Scalar>& args);

double evaluate(const Expr& e, double time);

// The largest |constant| in the expression (what the shader must represent).
double largestConstant(const Scalar& s);

}  // namespace sdfc::ir
