#include "ir/expr.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace sdfc::ir {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct FunctionInfo {
  const char* name;
  int arity;
  double (*fn)(const double*);
};

const FunctionInfo kFunctions[] = {
    {"sin", 1, [](const double* a) { return std::sin(a[0]); }},
    {"cos", 1, [](const double* a) { return std::cos(a[0]); }},
    {"tan", 1, [](const double* a) { return std::tan(a[0]); }},
    {"abs", 1, [](const double* a) { return std::fabs(a[0]); }},
    {"sqrt", 1, [](const double* a) { return std::sqrt(a[0]); }},
    {"exp", 1, [](const double* a) { return std::exp(a[0]); }},
    {"floor", 1, [](const double* a) { return std::floor(a[0]); }},
    {"fract", 1, [](const double* a) { return a[0] - std::floor(a[0]); }},
    {"radians", 1, [](const double* a) { return a[0] * M_PI / 180.0; }},
    {"min", 2, [](const double* a) { return std::min(a[0], a[1]); }},
    {"max", 2, [](const double* a) { return std::max(a[0], a[1]); }},
    {"pow", 2, [](const double* a) { return std::pow(a[0], a[1]); }},
    {"clamp", 3, [](const double* a) { return std::clamp(a[0], a[1], std::max(a[1], a[2])); }},
    {"mix", 3, [](const double* a) { return a[0] + (a[1] - a[0]) * a[2]; }},
    {"smoothstep", 3,
     [](const double* a) {
       const double t = std::clamp((a[2] - a[0]) / (a[1] - a[0]), 0.0, 1.0);
       return t * t * (3 - 2 * t);
     }},
};

const FunctionInfo* findFunction(const std::string& name) {
  for (const FunctionInfo& f : kFunctions)
    if (name == f.name) return &f;
  return nullptr;
}

std::string number(double v) {
  std::ostringstream out;
  out.precision(9);
  out << v;
  std::string s = out.str();
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

// Interval arithmetic over all times, with the conventions 0 * inf = 0 and
// inf - inf = the widest bound, so an unbounded input never yields NaN.
double lower(double v) { return std::isnan(v) ? -kInf : v; }
double higher(double v) { return std::isnan(v) ? kInf : v; }
double product(double a, double b) { return a == 0 || b == 0 ? 0 : a * b; }

// Structural equality, so that `time * time` is known to be a square.
bool sameExpr(const Expr& a, const Expr& b) {
  if (&a == &b) return true;
  if (a.op != b.op || a.value != b.value || a.function != b.function || a.args.size() != b.args.size() ||
      a.size != b.size)
    return false;
  for (size_t i = 0; i < a.args.size(); ++i)
    if (!sameExpr(*a.args[i], *b.args[i])) return false;
  return true;
}

Interval rangeOf(const Expr& e) {
  switch (e.op) {
    case Expr::Op::Const: return {e.value, e.value};
    case Expr::Op::Time: return {-kInf, kInf};
    case Expr::Op::Neg: {
      Interval a = rangeOf(*e.args[0]);
      return {-a.hi, -a.lo};
    }
    case Expr::Op::Add: {
      Interval a = rangeOf(*e.args[0]), b = rangeOf(*e.args[1]);
      return {lower(a.lo + b.lo), higher(a.hi + b.hi)};
    }
    case Expr::Op::Sub: {
      Interval a = rangeOf(*e.args[0]), b = rangeOf(*e.args[1]);
      return {lower(a.lo - b.hi), higher(a.hi - b.lo)};
    }
    case Expr::Op::Mul: {
      Interval a = rangeOf(*e.args[0]);
      if (sameExpr(*e.args[0], *e.args[1])) {  // a square is never negative
        const double top = std::max(product(a.lo, a.lo), product(a.hi, a.hi));
        const double bottom = a.lo <= 0 && a.hi >= 0 ? 0 : std::min(product(a.lo, a.lo), product(a.hi, a.hi));
        return {bottom, top};
      }
      return multiply(a, rangeOf(*e.args[1]));
    }
    case Expr::Op::Div: {
      Interval a = rangeOf(*e.args[0]), b = rangeOf(*e.args[1]);
      if (b.lo <= 0 && b.hi >= 0) return {-kInf, kInf};
      return multiply(a, {1 / b.hi, 1 / b.lo});
    }
    case Expr::Op::Call: {
      const std::string& f = e.function;
      if (f == "sin" || f == "cos") return {-1, 1};
      if (f == "smoothstep") return {0, 1};
      if (f == "fract") return {0, 1};
      if (f == "clamp") {
        Interval lo = rangeOf(*e.args[1]), hi = rangeOf(*e.args[2]);
        return {lo.lo, std::max(lo.hi, hi.hi)};
      }
      if (f == "abs") {
        Interval a = rangeOf(*e.args[0]);
        if (a.lo >= 0) return a;
        return {0, std::max(-a.lo, a.hi)};
      }
      if (f == "min" || f == "max") {
        Interval a = rangeOf(*e.args[0]), b = rangeOf(*e.args[1]);
        if (f == "min") return {std::min(a.lo, b.lo), std::min(a.hi, b.hi)};
        return {std::max(a.lo, b.lo), std::max(a.hi, b.hi)};
      }
      if (f == "mix") {
        Interval a = rangeOf(*e.args[0]), b = rangeOf(*e.args[1]), t = rangeOf(*e.args[2]);
        if (t.lo >= 0 && t.hi <= 1) return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
      }
      // Monotonic functions map the bounds (where defined: sqrt of the
      // non-negative part; its negative part is reported by the checker).
      if (f == "sqrt") {
        Interval a = rangeOf(*e.args[0]);
        return {std::sqrt(std::max(a.lo, 0.0)), std::sqrt(std::max(a.hi, 0.0))};
      }
      if (f == "exp") {
        Interval a = rangeOf(*e.args[0]);
        return {std::exp(a.lo), std::exp(a.hi)};
      }
      if (f == "floor") {
        Interval a = rangeOf(*e.args[0]);
        return {std::floor(a.lo), std::floor(a.hi)};
      }
      if (f == "radians") {
        Interval a = rangeOf(*e.args[0]);
        return {a.lo * M_PI / 180.0, a.hi * M_PI / 180.0};
      }
      return {-kInf, kInf};
    }
  }
  return {-kInf, kInf};
}

double largestConstantOf(const Expr& e) {
  double m = e.op == Expr::Op::Const ? std::fabs(e.value) : 0;
  for (const ExprRef& a : e.args) m = std::max(m, largestConstantOf(*a));
  return m;
}

std::string glslOf(const Expr& e, bool for_glsl) {
  switch (e.op) {
    case Expr::Op::Const: return number(e.value);
    case Expr::Op::Time: return for_glsl ? "frame.cam_forward.w" : "time";
    case Expr::Op::Neg: return "(-" + glslOf(*e.args[0], for_glsl) + ")";
    case Expr::Op::Add:
    case Expr::Op::Sub:
    case Expr::Op::Mul:
    case Expr::Op::Div: {
      const char op = e.op == Expr::Op::Add ? '+' : e.op == Expr::Op::Sub ? '-'
                    : e.op == Expr::Op::Mul ? '*' : '/';
      return "(" + glslOf(*e.args[0], for_glsl) + " " + op + " " + glslOf(*e.args[1], for_glsl) +
             ")";
    }
    case Expr::Op::Call: {
      std::string name = e.function;
      std::string s = name + "(";
      for (size_t i = 0; i < e.args.size(); ++i)
        s += (i ? ", " : "") + glslOf(*e.args[i], for_glsl);
      return s + ")";
    }
  }
  return "0.0";
}

Scalar fromExpr(Expr e, double time0_value) {
  for (const ExprRef& a : e.args) e.size += a->size;
  e.size = std::min(e.size, 1e18);
  Scalar s;
  s.value = time0_value;
  s.expr = std::make_shared<const Expr>(std::move(e));
  return s;
}

ExprRef asExpr(const Scalar& s) {
  if (s.expr) return s.expr;
  auto e = std::make_shared<Expr>();
  e->op = Expr::Op::Const;
  e->value = s.value;
  return e;
}

}  // namespace

Interval multiply(Interval a, Interval b) {
  const double c[] = {product(a.lo, b.lo), product(a.lo, b.hi), product(a.hi, b.lo), product(a.hi, b.hi)};
  return {*std::min_element(c, c + 4), *std::max_element(c, c + 4)};
}

bool Interval::bounded() const { return std::isfinite(lo) && std::isfinite(hi); }

double evaluate(const Expr& e, double time) {
  switch (e.op) {
    case Expr::Op::Const: return e.value;
    case Expr::Op::Time: return time;
    case Expr::Op::Neg: return -evaluate(*e.args[0], time);
    case Expr::Op::Add: return evaluate(*e.args[0], time) + evaluate(*e.args[1], time);
    case Expr::Op::Sub: return evaluate(*e.args[0], time) - evaluate(*e.args[1], time);
    case Expr::Op::Mul: return evaluate(*e.args[0], time) * evaluate(*e.args[1], time);
    case Expr::Op::Div: return evaluate(*e.args[0], time) / evaluate(*e.args[1], time);
    case Expr::Op::Call: {
      double a[3] = {0, 0, 0};
      for (size_t i = 0; i < e.args.size() && i < 3; ++i) a[i] = evaluate(*e.args[i], time);
      const FunctionInfo* f = findFunction(e.function);
      return f ? f->fn(a) : 0.0;
    }
  }
  return 0;
}

double largestConstant(const Scalar& s) {
  return s.expr ? largestConstantOf(*s.expr) : std::fabs(s.value);
}

double Scalar::at(double time) const { return expr ? evaluate(*expr, time) : value; }
Interval Scalar::range() const { return expr ? rangeOf(*expr) : Interval{value, value}; }
std::string Scalar::glsl() const { return expr ? glslOf(*expr, true) : number(value); }
std::string Scalar::text() const { return expr ? glslOf(*expr, false) : number(value); }

Scalar constant(double v) { return Scalar{v, nullptr}; }

Scalar timeScalar() {
  Expr e;
  e.op = Expr::Op::Time;
  return fromExpr(std::move(e), 0.0);
}

Scalar unary(char op, const Scalar& a) {
  if (a.isConst()) return constant(-a.value);
  Expr e;
  e.op = Expr::Op::Neg;
  e.args = {a.expr};
  return fromExpr(std::move(e), -a.value);
}

Scalar binary(char op, const Scalar& a, const Scalar& b) {
  auto apply = [op](double x, double y) {
    switch (op) {
      case '+': return x + y;
      case '-': return x - y;
      case '*': return x * y;
      default: return x / y;
    }
  };
  if (a.isConst() && b.isConst()) return constant(apply(a.value, b.value));
  Expr e;
  e.op = op == '+' ? Expr::Op::Add : op == '-' ? Expr::Op::Sub : op == '*' ? Expr::Op::Mul
                                                                           : Expr::Op::Div;
  e.args = {asExpr(a), asExpr(b)};
  return fromExpr(std::move(e), apply(a.value, b.value));
}

const std::vector<std::string>& mathFunctionNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const FunctionInfo& f : kFunctions) v.push_back(f.name);
    return v;
  }();
  return names;
}

int mathFunctionArity(const std::string& name) {
  const FunctionInfo* f = findFunction(name);
  return f ? f->arity : -1;
}

Scalar callFunction(const std::string& name, const std::vector<Scalar>& args) {
  const FunctionInfo* f = findFunction(name);
  double a[3] = {0, 0, 0};
  bool all_const = true;
  for (size_t i = 0; i < args.size() && i < 3; ++i) {
    a[i] = args[i].value;
    all_const = all_const && args[i].isConst();
  }
  const double v = f ? f->fn(a) : 0.0;
  if (all_const) return constant(v);
  Expr e;
  e.op = Expr::Op::Call;
  e.function = name;
  for (const Scalar& s : args) e.args.push_back(asExpr(s));
  return fromExpr(std::move(e), v);
}

}  // namespace sdfc::ir
