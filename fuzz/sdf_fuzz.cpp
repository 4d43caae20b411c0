// libFuzzer target: the whole front end (lexer, parser, checker, passes)
// on arbitrary bytes. Any crash, sanitizer report or hang is a bug: every
// input must end in diagnostics or a checked scene.
#include <cstddef>
#include <cstdint>
#include <string>

#include "driver/compile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  sdfc::Diagnostics diags;
  sdfc::CompiledScene compiled =
      sdfc::checkSource("fuzz.sdf", std::move(text), sdfc::CompileOptions{}, diags);
  // The formatters walk every range the parser and checker produced.
  (void)diags.format();
  (void)diags.formatJson();
  // A scene without errors must be a usable scene.
  if (!diags.hasErrors() && !compiled.ok) __builtin_trap();
  return 0;
}
