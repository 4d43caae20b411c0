// The checker: resolves names, checks types, arity, units and values, and
// builds the IR scene. It reports every problem it finds, as diagnostics.
#pragma once
#include <map>
#include <string>

#include "diag/diagnostics.h"
#include "ir/scene.h"
#include "syntax/ast.h"

namespace sdfc {

struct CheckOptions {
  // -D name=value: replaces the number bound by `let name` before checking.
  std::map<std::string, double> defines;
  // mesh(file: ...) in the shader: Auto lets the compiler choose (--mesh-mode).
  MeshMode mesh_mode = MeshMode::Auto;
};

// Limits that keep the emitted shader sane; the messages quote them.
constexpr int kMaxRepeatCount = 10000;
// displace's octaves are unrolled in the shader (no loop against lavapipe's cap).
constexpr int kMaxDisplaceOctaves = 8;
constexpr int kMaxImageSide = 16384;
constexpr int kMaxSamples = 1 << 20;
constexpr int kMaxBounces = 64;
// Instance indices reach the shader as float32 values: exact below 2^24.
constexpr size_t kMaxInstances = size_t(1) << 23;
// runtime/loop_budget.h's kMaxLights: the kernel's light loop is bounded by it.
constexpr int kMaxLights = 16;
// morph's |t| + |1 - t| over time (t within [-3.5, 4.5]).
constexpr double kMaxMorphStretch = 8;
// Operations in one time-dependent expression as written into the shader.
constexpr int kMaxTimeExpressionSize = 10000;
// Shape nodes (primitives and operations, shared ones once) in a scene.
constexpr int kMaxSceneNodes = 4096;
// Shape nodes with every use of a definition written out: each use is
// evaluated at every point, and the driver inlines the shader's functions, so
// a definition that uses the previous one twice, 20 times over, must not check.
constexpr size_t kMaxExpandedNodes = 16384;

ir::Scene check(const ast::File& file, const SourceFile& source, Diagnostics& diags,
                const CheckOptions& options = {});

}  // namespace sdfc
