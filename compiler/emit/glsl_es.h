// The emitted Vulkan GLSL 4.50 kernel rewritten as GLSL ES 3.00 for WebGL2
// and Shadertoy (`sdfc export`, docs/export.md; why a rewrite of our own text
// rather than SPIRV-Cross: docs/design/web_export.md). The kernel's code stays
// the same text; only its interface changes:
//   - FrameParams comes from `uniform FrameParams frame;` instead of push constants;
//   - the instances' data (sd_data[i]) is read from an RGBA32F texture of
//     kEsDataWidth texels a row (sdData(i)), since ES 3.00 has no storage buffers;
//   - subgroupAny / subgroupAll become the lane's own condition (a subgroup of one);
//   - bitfieldReverse (ES 3.10) is written out; function-local `const`s with a
//     run-time initializer (GLSL 4.20) lose the `const`.
// Shadertoy: no #version, no precision, no outputs: `void main()` becomes
// `void sdfcKernel()` writing globals, and a mainImage() fills `frame`.
#pragma once
#include <string>

namespace sdfc {

enum class EsTarget { WebGl2, Shadertoy };

// Texels per row of the scene-data texture: WebGL2 guarantees textures of
// 2048 x 2048 (MAX_TEXTURE_SIZE), so this width with up to 2048 rows fits
// every browser: at most kEsDataWidth * kEsMaxDataRows vec4s of data.
inline constexpr int kEsDataWidth = 2048;
inline constexpr int kEsMaxDataRows = 2048;

struct GlslEsResult {
  std::string glsl;
  std::string error;  // non-empty: the kernel uses something with no ES 3.00 form
  bool ok() const { return error.empty(); }
};

GlslEsResult toGlslEs(const std::string& vulkan_glsl, EsTarget target);

// glslang's verdict on `source` as a GLSL ES 3.00 fragment shader (parse and
// semantic checks, no code generation): "" when valid, else its messages.
// Shadertoy code is checked inside a stand-in for Shadertoy's own wrapper.
std::string validateGlslEs(const std::string& source, EsTarget target);

}  // namespace sdfc
