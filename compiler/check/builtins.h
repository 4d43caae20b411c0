// Signatures of the built-in operators, materials and settings (primitives
// live in shapes/primitives.h). The checker binds call arguments against these.
#pragma once
#include <string>
#include <vector>

#include "shapes/primitives.h"

namespace sdfc {

// Colour: a 3-vector (or a number for a grey), or a colour field where a
// material takes it.
enum class ArgType { Number, Vector3, Vector2, Colour, Any };
enum class ValueRule { Any, Positive, NonNegative };

struct ArgSpec {
  const char* name;
  ArgType type;
  ValueRule rule;
  bool required;
  bool time_allowed;
  bool nonzero = false;  // vectors: the zero vector is rejected
};

enum class BuiltinCategory { Operator, Material, Field, Setting };

struct BuiltinSignature {
  const char* name;
  BuiltinCategory category;
  std::vector<ArgSpec> args;
  const char* summary;
};

const std::vector<BuiltinSignature>& builtinSignatures();
const BuiltinSignature* findBuiltin(const std::string& name);
bool isSettingName(const std::string& name);
// Names a `let` may not take: built-ins and `time`, `pi`, `scene`.
bool isReservedName(const std::string& name);
bool isBuiltinCallable(const std::string& name);
std::vector<std::string> allCallableNames();
ArgSpec argSpecOf(const ParamSpec& param, const PrimitiveInfo& info);

}  // namespace sdfc
