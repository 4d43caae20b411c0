// Diagnostics as data: collected in a list, printed by one formatter in the
// form gcc and clang use (file:line:col: error: message, source line, caret).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "diag/source.h"

namespace sdfc {

enum class Severity { Error, Warning, Note };

struct Diagnostic {
  Severity severity = Severity::Error;
  SourceRange range;
  std::string message;
  std::vector<Diagnostic> notes;
};

class Diagnostics {
 public:
  Diagnostic& error(SourceRange range, std::string message);
  Diagnostic& warning(SourceRange range, std::string message);
  Diagnostic& add(Diagnostic d);  // a diagnostic made elsewhere (an error counts as one)
  bool hasErrors() const { return error_count_ > 0; }
  int errorCount() const { return error_count_; }
  const std::vector<Diagnostic>& all() const { return list_; }
  // Every diagnostic in source order, each with its line and caret.
  std::string format(bool color = false) const;
  // The same as a JSON array (for --diagnostics-format json).
  std::string formatJson() const;
  // Keeps a file other than the scene alive as long as the diagnostics that
  // point into it (a CSV read by instances(positions: file(...))).
  const SourceFile& keep(std::unique_ptr<SourceFile> file);

 private:
  std::vector<Diagnostic> list_;
  std::vector<std::shared_ptr<const SourceFile>> kept_;
  int error_count_ = 0;
};

std::string formatDiagnostic(const Diagnostic& d, bool color = false);

// Edit distance, for "did you mean ...?" suggestions.
size_t editDistance(const std::string& a, const std::string& b);
// The candidate closest to `name`, or "" when none is close enough to suggest.
std::string nearestName(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace sdfc
