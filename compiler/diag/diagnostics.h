// Diagnostics as data: collected in a list, printed by one formatter in the
// form gcc and clang use (file:line:col: error: message, source line, caret).
#pragma once
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "diag/source.h"

namespace sdfc {

enum class Severity { Error, Warning, Note };

struct Diagnostic {
  Diagnostic() = default;
  Diagnostic(Severity severity_, SourceRange range_, std::string message_,
             std::vector<Diagnostic> notes_ = {}, std::string name_ = {})
      : severity(severity_), range(range_), message(std::move(message_)), notes(std::move(notes_)),
        name(std::move(name_)) {}
  Severity severity = Severity::Error;
  SourceRange range;
  std::string message;
  std::vector<Diagnostic> notes;
  std::string name;  // a warning's name (diag/warnings.h): printed as [-Wname], silenced by -Wno-name
};

// What the command line's --error-limit defaults to (clang's figure).
inline constexpr int kDefaultErrorLimit = 20;

class Diagnostics {
 public:
  Diagnostic& error(SourceRange range, std::string message);
  // `name` is one of kWarnings (diag/warnings.h). A warning turned off by
  // disableWarning or allowed where it points (allowIn) is counted, not kept.
  Diagnostic& warning(SourceRange range, const char* name, std::string message);
  Diagnostic& add(Diagnostic d);  // a diagnostic made elsewhere (an error counts as one)
  bool hasErrors() const { return error_count_ > 0; }
  int errorCount() const { return error_count_; }
  int warningCount() const { return warning_count_; }
  int suppressedCount() const { return suppressed_count_; }
  const std::vector<Diagnostic>& all() const { return list_; }
  // Warnings named here are not reported anywhere (-Wno-NAME).
  void disableWarning(const std::string& name) { disabled_.insert(name); }
  // Warnings named `name` that point inside `region` are not reported (a
  // `// sdfc: allow(...)` comment in the scene, syntax/pragmas.h).
  void allowIn(SourceRange region, const std::string& name);
  // Every diagnostic in source order, each with its line and caret. With
  // error_limit > 0, printing stops after that many errors, with a note
  // saying how many were left out.
  std::string format(bool color = false, int error_limit = 0) const;
  // The same as a JSON array (for --diagnostics-format json), in the same
  // order and under the same limit.
  std::string formatJson(int error_limit = 0) const;
  // Keeps a file other than the scene alive as long as the diagnostics that
  // point into it (a CSV read by instances(positions: file(...))).
  const SourceFile& keep(std::unique_ptr<SourceFile> file);

 private:
  struct Allowed {
    SourceRange region;
    std::string name;
  };
  bool isSuppressed(const SourceRange& range, const std::string& name) const;
  std::vector<const Diagnostic*> sorted() const;
  std::vector<Diagnostic> list_;
  std::vector<std::shared_ptr<const SourceFile>> kept_;
  int error_count_ = 0;
  int warning_count_ = 0;
  int suppressed_count_ = 0;
  Diagnostic scratch_;  // what a suppressed warning's caller writes its notes into
  std::set<std::string> disabled_;
  std::vector<Allowed> allowed_;
};

// One diagnostic as text; a source line wider than about 160 columns is
// shown as a window around the caret, so the output stays small.
std::string formatDiagnostic(const Diagnostic& d, bool color = false);

// Edit distance, for "did you mean ...?" suggestions.
size_t editDistance(const std::string& a, const std::string& b);
// The candidate closest to `name`, or "" when none is close enough to suggest.
std::string nearestName(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace sdfc
