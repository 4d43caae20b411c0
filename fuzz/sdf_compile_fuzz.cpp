// libFuzzer target: every input the checker accepts goes on through the
// emitter and glslang (GLSL -> validated SPIR-V), as `sdfc compile` would.
// A checked scene that fails to compile is a finding (abort): the checker
// must reject whatever the shader cannot represent, with a diagnostic.
// Inputs the checker rejects cost little, so the fuzzer spends its time on
// scenes that reach the back end.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "driver/compile.h"

namespace {

// How many inputs reached glslang, printed at exit (libFuzzer's figures
// count rejected inputs too).
struct Counts {
  long inputs = 0, compiled = 0;
  ~Counts() {
    std::fprintf(stderr, "sdfc_compile_fuzz: %ld inputs, %ld checked and compiled to SPIR-V\n", inputs,
                 compiled);
  }
} counts;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ++counts.inputs;
  std::string text(reinterpret_cast<const char*>(data), size);
  sdfc::Diagnostics check_diags;
  sdfc::CompileOptions options;
  const sdfc::CompiledScene checked = sdfc::checkSource("fuzz.sdf", text, options, check_diags);
  if (!checked.ok) return -1;  // rejected: not worth adding to the corpus for this target
  sdfc::Diagnostics diags;
  const sdfc::CompiledScene compiled = sdfc::compileSource("fuzz.sdf", std::move(text), options, diags);
  if (!compiled.ok || compiled.spirv.empty()) {
    std::fprintf(stderr, "sdfc_compile_fuzz: a checked scene does not compile:\n%s\n",
                 diags.format().c_str());
    std::abort();
  }
  ++counts.compiled;
  return 0;
}
