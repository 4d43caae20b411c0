// What the editor says about a built-in, drawn from the compiler's one
// catalogue (check/builtins, shapes/primitives, ir math functions): the
// signature, each parameter's type, rule and default, and exactness.
#pragma once
#include <string>
#include <vector>

namespace sdfc::lsp {

struct ParamDoc {
  std::string name;
  std::string type;      // "number", "vector", "number or vector", "material"
  std::string rule;      // "> 0", ">= 0", "non-zero", "" for any value
  std::string fallback;  // default value as written, "" when required or unknown
  bool required = false;
  bool time_allowed = true;
  std::string label() const;  // `radius: number = 1`
};

enum class CalleeKind { Primitive, Operator, Material, Field, Setting, Math, Scene, Definition };

struct CalleeDoc {
  std::string name;
  CalleeKind kind;
  std::string summary;
  std::vector<ParamDoc> params;
  bool exact = true;  // primitives: an exact Euclidean distance
  std::string signature() const;
  std::string markdown() const;  // for hover and completion documentation
};

const std::vector<CalleeDoc>& callees();
const CalleeDoc* findCallee(const std::string& name);
const char* kindName(CalleeKind kind);

}  // namespace sdfc::lsp
