// GLSL -> SPIR-V in process, through glslang linked as a library, then
// validated (and optionally optimized) with SPIRV-Tools.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace sdfc {

enum class ShaderStage { Vertex, Fragment };

struct SpirvResult {
  std::vector<std::uint32_t> words;  // empty on failure
  std::string log;                   // glslang / validator messages
  bool ok() const { return !words.empty(); }
};

// `name` is used in messages ("castle.sdf.glsl:12: ..."). When `optimize` is
// set, spirv-opt's performance passes run before validation.
SpirvResult glslToSpirv(const std::string& source, ShaderStage stage, const std::string& name,
                        bool optimize = false);

// Human-readable SPIR-V assembly, for --emit spvasm.
std::string disassembleSpirv(const std::vector<std::uint32_t>& words);

}  // namespace sdfc
