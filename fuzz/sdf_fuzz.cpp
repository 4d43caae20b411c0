// libFuzzer target: the whole front end (lexer, parser, checker, passes)
// on arbitrary bytes. Any crash, sanitizer report, hang or broken invariant
// (fuzz/invariants.h) is a bug: every input must end in diagnostics or a
// usable checked scene.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "driver/compile.h"
#include "fuzz/invariants.h"

namespace {

// The finiteness check is on unless SDFC_FUZZ_FINITE=0 (the checker rejects
// arithmetic that overflows; fuzz/regressions/nonfinite_*.sdf pin it).
bool checkFinite() {
  static const bool on = [] {
    const char* v = std::getenv("SDFC_FUZZ_FINITE");
    return !(v && std::string(v) == "0");
  }();
  return on;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  sdfc::Diagnostics diags;
  sdfc::CompiledScene compiled =
      sdfc::checkSource("fuzz.sdf", std::move(text), sdfc::CompileOptions{}, diags);
  // The formatters walk every range the parser and checker produced.
  (void)diags.format();
  (void)diags.formatJson();
  const std::string broken = sdfc::fuzz::violatedInvariant(compiled, diags, checkFinite());
  if (!broken.empty()) {
    std::fprintf(stderr, "sdfc_fuzz: invariant broken: %s\n", broken.c_str());
    std::abort();
  }
  return 0;
}
