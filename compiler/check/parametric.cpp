#include "check/parametric.h"

#include <cstdio>

#include "check/builtins.h"
#include "shapes/primitives.h"

namespace sdfc {
namespace {

ParamUse useOfSpec(ArgType type) {
  switch (type) {
    case ArgType::Number: return ParamUse::Number;
    case ArgType::Vector3:
    case ArgType::Vector2: return ParamUse::Numeric;  // a number stands for a uniform vector
    case ArgType::Colour:  // a colour or a colour field
    case ArgType::Any: return ParamUse::Unknown;
  }
  return ParamUse::Unknown;
}

class UseFinder {
 public:
  UseFinder(const ast::Statement& def) : def_(def), uses_(def.params.size()) {}

  std::vector<ParamUsage> run() {
    for (const ast::Parameter& p : def_.params)
      if (p.default_value) walk(*p.default_value, ParamUse::Unknown);
    walk(*def_.value, ParamUse::Unknown);
    return uses_;
  }

 private:
  const ast::Statement& def_;
  std::vector<ParamUsage> uses_;

  void walk(const ast::Expr& e, ParamUse context) {
    switch (e.kind) {
      case ast::ExprKind::Name:
        for (size_t i = 0; i < def_.params.size(); ++i)
          if (def_.params[i].name == e.name && uses_[i].use == ParamUse::Unknown && context != ParamUse::Unknown)
            uses_[i] = {context, e.range};
        return;
      case ast::ExprKind::Vector:
        for (const ast::ExprPtr& o : e.operands) walk(*o, ParamUse::Number);
        return;
      case ast::ExprKind::Unary:
      case ast::ExprKind::Binary:
        for (const ast::ExprPtr& o : e.operands) walk(*o, ParamUse::Numeric);
        return;
      case ast::ExprKind::Member:
        walk(*e.operands[0], ParamUse::Vector);
        return;
      case ast::ExprKind::Call: walkCall(e); return;
      default: return;
    }
  }

  void walkCall(const ast::Expr& e) {
    // The parameter list of a built-in callee, as uses.
    std::vector<std::pair<std::string, ParamUse>> params;
    const bool math = ir::mathFunctionArity(e.name) >= 0;
    if (const PrimitiveInfo* prim = findPrimitive(e.name)) {
      for (const ParamSpec& p : prim->params)
        params.push_back({p.name, p.type == ParamType::Number ? ParamUse::Number
                                  : p.type == ParamType::Points ? ParamUse::Unknown
                                                                : ParamUse::Numeric});
    } else if (const BuiltinSignature* sig = findBuiltin(e.name)) {
      for (const ArgSpec& a : sig->args) params.push_back({a.name, useOfSpec(a.type)});
    }
    size_t positional = 0;
    for (const ast::Argument& a : e.arguments) {
      ParamUse use = math ? ParamUse::Number : ParamUse::Unknown;
      if (a.name == "material") {
        use = ParamUse::Material;
      } else if (a.name.empty()) {
        if (positional < params.size()) use = params[positional].second;
        ++positional;
      } else {
        for (const auto& [name, u] : params)
          if (name == a.name) use = u;
      }
      walk(*a.value, use);
    }
    for (const ast::ExprPtr& c : e.children) walk(*c, ParamUse::Shape);
  }
};

void exprKey(const ir::Expr& e, std::string& out) {
  char buf[40];
  switch (e.op) {
    case ir::Expr::Op::Const: std::snprintf(buf, sizeof buf, "%.17g", e.value); out += buf; return;
    case ir::Expr::Op::Time: out += "time"; return;
    case ir::Expr::Op::Add: out += "+("; break;
    case ir::Expr::Op::Sub: out += "-("; break;
    case ir::Expr::Op::Mul: out += "*("; break;
    case ir::Expr::Op::Div: out += "/("; break;
    case ir::Expr::Op::Neg: out += "neg("; break;
    case ir::Expr::Op::Call: out += e.function + "("; break;
  }
  for (const ir::ExprRef& a : e.args) {
    exprKey(*a, out);
    out += ",";
  }
  out += ")";
}

}  // namespace

std::vector<ParamUsage> inferParameterUses(const ast::Statement& definition) {
  return UseFinder(definition).run();
}

const char* paramUseName(ParamUse use) {
  switch (use) {
    case ParamUse::Number: return "a number";
    case ParamUse::Numeric: return "a number or a vector";
    case ParamUse::Vector: return "a vector";
    case ParamUse::Shape: return "a shape";
    case ParamUse::Material: return "a material";
    case ParamUse::Unknown: return "any value";
  }
  return "a value";
}

std::string scalarKey(const ir::Scalar& s) {
  if (s.isConst()) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", s.value);
    return buf;
  }
  std::string out;
  exprKey(*s.expr, out);
  return out;
}

}  // namespace sdfc
