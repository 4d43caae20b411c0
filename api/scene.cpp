#include "api/scene.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>

namespace sdfc::api {

CompileOptions LoadOptions::defaultCompileOptions(KernelView view) {
  CompileOptions o;  // the compiler's defaults are the command line's, but for these
  o.emit.view = view;
  o.cache_version = kVersion;
  return o;
}

bool Scene::ok() const {
  return io_error.empty() && !diagnostics.hasErrors() &&
         !(options.werror && diagnostics.warningCount() > 0) && compiled.scene.root;
}

std::string Scene::diagnosticsText(bool color, int error_limit) const {
  return diagnostics.format(color, error_limit);
}

std::string Scene::diagnosticsJson(int error_limit) const { return diagnostics.formatJson(error_limit); }

namespace {

DiagnosticRecord recordOf(const Diagnostic& d) {
  DiagnosticRecord r;
  r.severity = d.severity == Severity::Error ? "error" : d.severity == Severity::Warning ? "warning" : "note";
  if (d.range.file) {
    r.file = d.range.file->path;
    std::tie(r.line, r.column) = d.range.file->lineColumn(d.range.begin);
  }
  r.message = d.message;
  r.name = d.name;
  for (const Diagnostic& n : d.notes) r.notes.push_back(recordOf(n));
  return r;
}

std::unique_ptr<Scene> load(const std::string& path, std::string text, const LoadOptions& options) {
  auto scene = std::make_unique<Scene>();
  scene->options = options;
  CompileOptions compile = options.compile;
  for (const auto& [name, value] : options.defines) compile.check.defines[name] = value;
  for (const std::string& name : options.disabled_warnings) scene->diagnostics.disableWarning(name);
  scene->compiled = options.emit ? compileSource(path, std::move(text), compile, scene->diagnostics)
                                 : checkSource(path, std::move(text), compile, scene->diagnostics);
  return scene;
}

}  // namespace

std::vector<DiagnosticRecord> Scene::diagnosticRecords() const {
  std::vector<DiagnosticRecord> out;
  for (const Diagnostic& d : diagnostics.all()) out.push_back(recordOf(d));
  return out;
}

CompiledScene Scene::compile(KernelView view, std::optional<int> height, bool spirv) const {
  CompileOptions o = options.compile;
  o.emit.view = view;
  if (height) o.emit.march.image_height = *height;
  o.produce_spirv = spirv;
  return compileWith(o);
}

CompiledScene Scene::compileWith(const CompileOptions& compile) const {
  if (!compiled.source) throw std::runtime_error("the scene has no source");
  LoadOptions o = options;
  o.compile = compile;
  o.emit = true;
  std::unique_ptr<Scene> again = load(compiled.source->path, compiled.source->text, o);
  if (!again->ok()) throw std::runtime_error(again->diagnosticsText());
  return std::move(again->compiled);
}

std::unique_ptr<Scene> loadFile(const std::string& path, const LoadOptions& options) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    auto scene = std::make_unique<Scene>();
    scene->options = options;
    scene->io_error = "cannot read '" + path + "': it is a directory, not a scene file";
    return scene;
  }
  std::unique_ptr<SourceFile> file = readSourceFile(path);
  if (!file) {
    auto scene = std::make_unique<Scene>();
    scene->options = options;
    const std::string why = sourceFileProblem(path);
    scene->io_error = "cannot read '" + path + "': " + (why.empty() ? std::strerror(errno) : why);
    return scene;
  }
  return load(path, std::move(file->text), options);
}

std::unique_ptr<Scene> loadString(const std::string& text, const std::string& name,
                                  const LoadOptions& options) {
  return load(name, text, options);
}

// Scanned by hand, not with std::regex: libstdc++'s regex recurses once per
// character, and a 30,000-digit -D value overflowed the stack.
bool isPlainNumber(std::string_view text) {
  size_t i = 0;
  const size_t n = text.size();
  auto digits = [&] {
    const size_t start = i;
    while (i < n && text[i] >= '0' && text[i] <= '9') ++i;
    return i - start;
  };
  if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
  size_t mantissa = digits();
  if (i < n && text[i] == '.') {
    ++i;
    mantissa += digits();
  }
  if (mantissa == 0) return false;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
    if (digits() == 0) return false;
  }
  return i == n;
}

std::optional<double> parsePlainNumber(const std::string& text) {
  if (!isPlainNumber(text)) return std::nullopt;
  const double value = std::strtod(text.c_str(), nullptr);
  if (!std::isfinite(value) || std::fabs(value) > std::numeric_limits<float>::max()) return std::nullopt;
  return value;
}

std::optional<std::pair<std::string, double>> parseDefine(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return std::nullopt;
  const std::optional<double> value = parsePlainNumber(text.substr(eq + 1));
  if (!value) return std::nullopt;
  return std::make_pair(text.substr(0, eq), *value);
}

}  // namespace sdfc::api
