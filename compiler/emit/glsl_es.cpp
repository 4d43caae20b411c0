#include "emit/glsl_es.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>

#include <mutex>
#include <sstream>

namespace sdfc {
namespace {

// Replaces the one line `from` (which the kernel must hold) with `to`.
bool replaceLine(std::string& text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos) return false;
  text.replace(at, from.size(), to);
  return true;
}

void replaceAll(std::string& text, const std::string& from, const std::string& to) {
  for (size_t at = 0; (at = text.find(from, at)) != std::string::npos; at += to.size())
    text.replace(at, from.size(), to);
}

// GLSL 4.20 lets a local const take a run-time value; ES does not. Dropping
// `const` from an indented (function-local) declaration changes nothing else.
std::string dropLocalConsts(const std::string& text) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line)) {
    const size_t first = line.find_first_not_of(" \t");
    if (first > 0 && first != std::string::npos && line.compare(first, 6, "const ") == 0)
      line.erase(first, 6);
    out += line;
    out += '\n';
  }
  return out;
}

// sd_data[expr] -> sdData(expr), brackets inside expr matched.
std::string readDataThroughTexture(const std::string& text) {
  static const std::string kArray = "sd_data[";
  std::string out;
  out.reserve(text.size());
  size_t i = 0;
  for (size_t j; (j = text.find(kArray, i)) != std::string::npos;) {
    out.append(text, i, j - i);
    size_t k = j + kArray.size();
    for (int depth = 1; k < text.size(); ++k) {
      depth += text[k] == '[';
      depth -= text[k] == ']';
      if (depth == 0) break;
    }
    out += "sdData(" + text.substr(j + kArray.size(), k - j - kArray.size()) + ")";
    i = k + 1;
  }
  out.append(text, std::min(i, text.size()), std::string::npos);
  return out;
}

// ES 3.00 lacks bitfieldReverse (the Sobol sampler's): the classic swap ladder.
constexpr const char* kBitfieldReverse =
    "uint bitfieldReverse(uint x) {\n"
    "  x = ((x >> 1u) & 0x55555555u) | ((x & 0x55555555u) << 1u);\n"
    "  x = ((x >> 2u) & 0x33333333u) | ((x & 0x33333333u) << 2u);\n"
    "  x = ((x >> 4u) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4u);\n"
    "  x = ((x >> 8u) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8u);\n"
    "  return (x >> 16u) | (x << 16u);\n"
    "}\n";

// What Shadertoy puts around an image tab's code (its uniforms and main), so
// the exported code can be checked here as it will be compiled there.
constexpr const char* kShadertoyHeader =
    "#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp sampler2D;\n"
    "uniform vec3 iResolution;\nuniform float iTime;\nuniform float iTimeDelta;\nuniform int iFrame;\n"
    "uniform vec4 iMouse;\nuniform vec4 iDate;\nuniform sampler2D iChannel0;\n";
constexpr const char* kShadertoyFooter =
    "\nout vec4 sdfc_shadertoy_out;\n"
    "void main() { mainImage(sdfc_shadertoy_out, gl_FragCoord.xy); }\n";

}  // namespace

GlslEsResult toGlslEs(const std::string& vulkan_glsl, EsTarget target) {
  GlslEsResult r;
  std::string s = vulkan_glsl;
  const bool shadertoy = target == EsTarget::Shadertoy;
  if (!replaceLine(s, "#version 450\n",
                   shadertoy ? "" : "#version 300 es\nprecision highp float;\nprecision highp int;\n"
                                    "precision highp sampler2D;\n")) {
    r.error = "the kernel has no '#version 450' line";
    return r;
  }
  if (s.find("#extension GL_GOOGLE_cpp_style_line_directive") != std::string::npos) {
    r.error = "--line-directives has no GLSL ES form";
    return r;
  }
  // A subgroup of one lane: the vote is the lane's own condition.
  replaceLine(s, "#extension GL_KHR_shader_subgroup_vote : require\n",
              "#define subgroupAny(b) (b)\n#define subgroupAll(b) (b)\n");
  const std::string frame = shadertoy ? "FrameParams frame;\n" : "uniform FrameParams frame;\n";
  if (!replaceLine(s, "layout(push_constant) uniform Push { FrameParams frame; };\n",
                   frame + kBitfieldReverse)) {
    r.error = "the kernel has no push-constant block";
    return r;
  }
  if (shadertoy) {
    // Outputs become globals the mainImage below reads; gl_FragCoord is
    // Shadertoy's fragCoord turned to Vulkan's top-left origin.
    for (int location = 0; location < 3; ++location)
      replaceAll(s, "layout(location = " + std::to_string(location) + ") out vec4 ", "vec4 ");
    replaceAll(s, "gl_FragCoord", "g_frag_coord");
    if (!replaceLine(s, "\nvoid main() {", "\nvoid sdfcKernel() {")) {
      r.error = "the kernel has no main()";
      return r;
    }
    replaceLine(s, "FrameParams frame;\n", "FrameParams frame;\nvec4 g_frag_coord;\n");
  }
  // No specialisation in GLSL ES: the kernel keeps what a capped driver runs.
  replaceLine(s, "layout(constant_id = 0) const bool kDriverCapsLoops = true;\n", "const bool kDriverCapsLoops = true;\n");
  // Storage buffer -> texture (the caller refuses data over the texture's size).
  replaceLine(s, "layout(std430, set = 0, binding = 0) readonly buffer SdfcSceneData { vec4 sd_data[]; };\n",
              "uniform highp sampler2D sd_data_tex;  // kEsDataWidth texels a row\n"
              "vec4 sdData(int i) { return texelFetch(sd_data_tex, ivec2(i & " +
                  std::to_string(kEsDataWidth - 1) + ", i >> " +
                  std::to_string(__builtin_ctz(unsigned(kEsDataWidth))) + "), 0); }\n");
  s = readDataThroughTexture(s);
  s = dropLocalConsts(s);
  r.glsl = std::move(s);
  return r;
}

std::string validateGlslEs(const std::string& source, EsTarget target) {
  static std::once_flag once;
  std::call_once(once, [] { glslang::InitializeProcess(); });
  const std::string text =
      target == EsTarget::Shadertoy ? kShadertoyHeader + source + kShadertoyFooter : source;
  glslang::TShader shader(EShLangFragment);
  const char* strings[] = {text.c_str()};
  shader.setStrings(strings, 1);
  // No client: the ES 3.00 language itself, as WebGL2 compiles it.
  if (shader.parse(GetDefaultResources(), 300, ENoProfile, false, false, EShMsgDefault)) return "";
  return shader.getInfoLog();
}

}  // namespace sdfc
