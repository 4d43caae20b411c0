// sdfc's public API, part 1: a scene loaded from a file or a string, with -D
// style overrides, its diagnostics as data, and its kernel (GLSL, SPIR-V) per
// view. The command line, the viewer, the language server and the Python
// module all load scenes through this; none of them prints from here.
#pragma once
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "driver/compile.h"

namespace sdfc {

// Exit codes: distinct per kind of failure, so scripts can tell them apart.
inline constexpr int kExitOk = 0;
inline constexpr int kExitScene = 1;      // the scene has errors
inline constexpr int kExitUsage = 2;      // bad command line
inline constexpr int kExitDevice = 3;     // Vulkan device or runtime failure
inline constexpr int kExitIo = 4;         // files that cannot be read or written
inline constexpr int kExitInterrupted = 130;

}  // namespace sdfc

namespace sdfc::api {

// sdfc's version: `--version`, the Python package and the SPIR-V cache key.
inline constexpr const char* kVersion = "0.1.0";

// What a front end may change about a load; the defaults are `sdfc check`'s.
struct LoadOptions {
  std::map<std::string, double> defines;        // -D name=value
  std::vector<std::string> disabled_warnings;   // -Wno-NAME
  bool werror = false;                          // warnings count as errors (ok() is false)
  CompileOptions compile = defaultCompileOptions();
  // Emit GLSL (and SPIR-V when compile.produce_spirv) as well as checking.
  bool emit = false;

  // The options `sdfc render` uses with no flags, for `view` (beauty, ...).
  static CompileOptions defaultCompileOptions(KernelView view = KernelView::Beauty);
};

// One diagnostic as plain data (notes flattened into `notes`).
struct DiagnosticRecord {
  std::string severity;  // "error", "warning" or "note"
  std::string file;
  int line = 0, column = 0;  // 1-based; 0 when it points at no source
  std::string message;
  std::string name;  // a warning's name (-Wno-NAME), else empty
  std::vector<DiagnosticRecord> notes;
};

class Scene {
 public:
  CompiledScene compiled;
  Diagnostics diagnostics;
  LoadOptions options;
  // Set when the file could not be read ("cannot read 'x': No such file or
  // directory"); the scene is then empty.
  std::string io_error;

  // Read and checked (and emitted, if asked) with no errors, and no warnings
  // under werror.
  bool ok() const;
  // Diagnostics exactly as `sdfc check` prints them (text or JSON).
  std::string diagnosticsText(bool color = false, int error_limit = kDefaultErrorLimit) const;
  std::string diagnosticsJson(int error_limit = kDefaultErrorLimit) const;
  std::vector<DiagnosticRecord> diagnosticRecords() const;

  // The scene's kernel for `view` under options.compile (with `height` the
  // march's image height, as `render --size WxH` sets it), compiled anew from
  // the source: the loaded scene itself is left as it is. Throws
  // std::runtime_error when the scene does not compile.
  CompiledScene compile(KernelView view, std::optional<int> height = std::nullopt,
                        bool spirv = true) const;
  // The same under other compiler options (the scene's defines and warnings).
  CompiledScene compileWith(const CompileOptions& options) const;
};

// Loads `path`. A file that cannot be read sets io_error (no exception).
std::unique_ptr<Scene> loadFile(const std::string& path, const LoadOptions& options = {});
// Loads `text`; `name` is what diagnostics call it (and where imports are
// resolved from: its folder).
std::unique_ptr<Scene> loadString(const std::string& text, const std::string& name = "<string>",
                                  const LoadOptions& options = {});

// A -D value as the command line takes it: a plain decimal number, finite in
// float32 ("-1.5e3"; no hex, inf or nan).
std::optional<double> parsePlainNumber(const std::string& text);
// The spelling parsePlainNumber takes ("1.", ".5", "-2e+3"), whatever its value.
bool isPlainNumber(std::string_view text);
// "name=value" -> the pair; nullopt when it is not one.
std::optional<std::pair<std::string, double>> parseDefine(const std::string& text);

}  // namespace sdfc::api
