// The syntax tree: exactly what was written, with source ranges. Meaning
// (names, types, units) is the checker's job.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "diag/source.h"

namespace sdfc::ast {

struct Expr;
using ExprPtr = std::unique_ptr<Expr>;

struct Argument {
  std::string name;  // empty for a positional argument
  SourceRange name_range;
  ExprPtr value;
};

enum class ExprKind { Number, String, Name, Vector, Unary, Binary, Member, Call, Error };

struct Expr {
  ExprKind kind = ExprKind::Error;
  SourceRange range;
  double number = 0;                // Number
  std::string name;                 // Name, Call (callee), Member (field), String (its text)
  SourceRange name_range;           // Call: the callee's range
  char op = 0;                      // Unary ('-'), Binary ('+', '-', '*', '/')
  std::vector<ExprPtr> operands;    // Vector elements; Unary/Binary/Member operands
  std::vector<Argument> arguments;  // Call: (...)
  bool has_block = false;           // Call: { ... } follows
  std::vector<ExprPtr> children;    // Call: the block's items
  // The outermost "(...)" written around it (file == nullptr when none): the
  // formatter keeps the parentheses; `range` itself never includes them.
  SourceRange paren_range;
  bool bad_name = false;            // Name, Call: already reported (non-ASCII name)
  bool reported = false;            // Vector: a syntax error inside was reported; the checker is silent
  int height = 1;                   // levels of this tree (later stages recurse that deep)
};

// A parameter of a parametric definition: `let tower(height, radius: 1) = ...`.
struct Parameter {
  std::string name;
  SourceRange name_range;
  ExprPtr default_value;  // null: the parameter must be given at every call
};

struct Statement {
  bool is_let = false;
  std::string name;  // let
  SourceRange name_range;
  // let: `(...)` was written after the name (a parametric definition, called
  // like a built-in), even when empty.
  bool has_params = false;
  std::vector<Parameter> params;
  SourceRange params_range;  // from "(" to ")"
  ExprPtr value;     // let: the bound value; otherwise the statement's call
  SourceRange range;
  // import "path" [as alias]: `import_path` is the string's text.
  bool is_import = false;
  std::string import_path;
  SourceRange import_path_range;
  std::string alias;  // empty: the definitions come in unqualified
  SourceRange alias_range;
};

struct File {
  std::vector<Statement> statements;
};

}  // namespace sdfc::ast
