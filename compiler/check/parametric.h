// Parametric definitions (`let tower(height, radius: 1) = ...`): what the
// checker needs beyond evaluating the body with the parameters bound. How
// the body uses each parameter (read from the syntax), so a call passing
// the wrong kind of value is reported at the call; and the key under which
// calls with equal arguments share one specialisation.
#pragma once
#include <string>
#include <vector>

#include "ir/expr.h"
#include "syntax/ast.h"

namespace sdfc {

// Number: a number only (a vector element, a math function's argument);
// Numeric: a number or a vector (arithmetic, a vector parameter).
enum class ParamUse { Unknown, Number, Numeric, Vector, Shape, Material };

struct ParamUsage {
  ParamUse use = ParamUse::Unknown;
  SourceRange where;  // the first use that says what it is
};

// One entry per parameter of `definition`, in order.
std::vector<ParamUsage> inferParameterUses(const ast::Statement& definition);
const char* paramUseName(ParamUse use);  // "a number", "a number or a vector", ...

// Exact text of a scalar (constants to 17 digits, time expressions whole):
// equal keys mean equal values at every time.
std::string scalarKey(const ir::Scalar& s);

}  // namespace sdfc
