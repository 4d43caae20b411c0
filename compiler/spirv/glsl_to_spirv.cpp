#include "spirv/glsl_to_spirv.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <spirv-tools/libspirv.hpp>
#include <spirv-tools/optimizer.hpp>

#include <chrono>
#include <mutex>

namespace sdfc {
namespace {

// glslang keeps process-wide tables; initialise them once and never tear
// down, so several compilations (tests, frame sequences) can share them.
void ensureGlslangInitialized() {
  static std::once_flag once;
  std::call_once(once, [] { glslang::InitializeProcess(); });
}

EShLanguage toGlslang(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::Vertex: return EShLangVertex;
    case ShaderStage::Compute: return EShLangCompute;
    default: return EShLangFragment;
  }
}

}  // namespace

SpirvResult glslToSpirv(const std::string& source, ShaderStage stage, const std::string& name,
                        bool optimize, bool validate) {
  ensureGlslangInitialized();
  const auto start = std::chrono::steady_clock::now();
  SpirvResult result;
  const EShLanguage lang = toGlslang(stage);
  glslang::TShader shader(lang);
  const char* text = source.c_str();
  const int length = static_cast<int>(source.size());
  const char* names = name.c_str();
  shader.setStringsWithLengthsAndNames(&text, &length, &names, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, lang, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_1);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_3);
  const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  if (!shader.parse(GetDefaultResources(), 450, false, messages)) {
    result.log = shader.getInfoLog();
    return result;
  }
  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages)) {
    result.log = program.getInfoLog();
    return result;
  }
  std::vector<std::uint32_t> words;
  spv::SpvBuildLogger logger;
  glslang::SpvOptions spv_options;
  spv_options.validate = false;  // SPIRV-Tools validates below, with better messages
  glslang::GlslangToSpv(*program.getIntermediate(lang), words, &logger, &spv_options);
  result.log = logger.getAllMessages();

  if (optimize) {
    spvtools::Optimizer opt(SPV_ENV_VULKAN_1_1);
    opt.RegisterPerformancePasses();
    std::vector<std::uint32_t> optimized;
    if (opt.Run(words.data(), words.size(), &optimized)) words.swap(optimized);
  }
  const auto compiled = std::chrono::steady_clock::now();
  result.compile_seconds = std::chrono::duration<double>(compiled - start).count();
  if (validate) {
    const std::string errors = validateSpirv(words);
    result.validate_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - compiled).count();
    if (!errors.empty()) {
      result.log += errors;
      return result;
    }
  }
  result.words = std::move(words);
  return result;
}

std::string validateSpirv(const std::vector<std::uint32_t>& words) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_1);
  std::string log;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos,
                               const char* msg) {
    log += "spirv-val: word " + std::to_string(pos.index) + ": " + msg + "\n";
  });
  if (tools.Validate(words)) return "";
  return log.empty() ? "spirv-val: invalid module\n" : log;
}

std::string disassembleSpirv(const std::vector<std::uint32_t>& words) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_1);
  std::string text;
  tools.Disassemble(words, &text, SPV_BINARY_TO_TEXT_OPTION_FRIENDLY_NAMES |
                                      SPV_BINARY_TO_TEXT_OPTION_INDENT);
  return text;
}

}  // namespace sdfc
