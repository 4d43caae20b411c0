// An on-disk cache of validated SPIR-V: a kernel compiled before skips glslang
// and the validator (on a small scene they were a third of the whole run). An
// entry's name is a hash of the GLSL, the options that change glslang's output and
// the versions of sdfc, glslang and SPIRV-Tools; it lives in
// $XDG_CACHE_HOME/sdfc/spirv (default ~/.cache/sdfc/spirv). Entries are written
// to a unique temporary and renamed, so concurrent runs never read half of one;
// an entry that fails its checks (magic, key, length, checksum, SPIR-V's magic
// word) is ignored, and the fresh compile replaces it. A cache that cannot be
// read or written is no error: the kernel is compiled as without one.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "spirv/glsl_to_spirv.h"

namespace sdfc {

// $XDG_CACHE_HOME/sdfc, else $HOME/.cache/sdfc; "" when neither is set.
std::string sdfcCacheDirectory();

// 32 hex digits naming the entry for `glsl` compiled with `options` (a text
// that changes whenever anything else changing glslang's output does).
std::string spirvCacheKey(const std::string& glsl, const std::string& options);

// The entry's words, or nullopt when it is absent or fails a check.
std::optional<std::vector<std::uint32_t>> loadCachedSpirv(const std::string& key);
// Stores validated `words` under `key` (temporary + rename); failures are ignored.
void storeCachedSpirv(const std::string& key, const std::vector<std::uint32_t>& words);
// Writes a cache file (SPIR-V here, the Vulkan pipeline cache beside it) best
// effort: a temporary beside it renamed over it, parent folders made; any
// failure leaves the old file or none, and says nothing (a cache is optional).
void writeCacheFile(const std::string& path, const std::string& bytes);
// The entry's path (for tests and messages).
std::string spirvCachePath(const std::string& key);

// glslToSpirv through the cache: a hit returns the stored words (validated when
// stored) and sets *hit; a miss compiles, and stores the words when they were
// validated. `version` is the caller's (sdfc's) version, part of the key.
SpirvResult cachedGlslToSpirv(const std::string& source, ShaderStage stage, const std::string& name,
                              bool optimize, bool validate, const std::string& version,
                              bool* hit = nullptr);

}  // namespace sdfc
