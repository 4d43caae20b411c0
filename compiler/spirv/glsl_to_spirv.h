// GLSL -> SPIR-V in process, through glslang linked as a library, then
// validated (and optionally optimized) with SPIRV-Tools.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace sdfc {

enum class ShaderStage { Vertex, Fragment, Compute };

struct SpirvResult {
  std::vector<std::uint32_t> words;  // empty on failure
  std::string log;                   // glslang / validator messages
  double compile_seconds = 0;        // glslang (and spirv-opt)
  double validate_seconds = 0;       // SPIRV-Tools' validator (0 when not run)
  bool from_cache = false;           // cachedGlslToSpirv: the words came from disk
  std::string cache_key;             // cachedGlslToSpirv: the entry's key
  bool ok() const { return !words.empty(); }
};

// `name` is used in messages ("castle.sdf.glsl:12: ..."). When `optimize` is
// set, spirv-opt's performance passes run before validation. Without
// `validate` the caller must run validateSpirv before the words reach a driver
// (sdfc view validates on a second thread while the driver builds the pipeline:
// on the castle validation is about half of GLSL -> SPIR-V).
SpirvResult glslToSpirv(const std::string& source, ShaderStage stage, const std::string& name,
                        bool optimize = false, bool validate = true);

// SPIRV-Tools' validator (Vulkan 1.1 rules): "" when valid, else its messages.
std::string validateSpirv(const std::vector<std::uint32_t>& words);

// Human-readable SPIR-V assembly, for --emit spvasm.
std::string disassembleSpirv(const std::vector<std::uint32_t>& words);

}  // namespace sdfc
