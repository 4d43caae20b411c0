#include "check/imports.h"

#include <filesystem>
#include <map>
#include <set>

#include "check/point_file.h"
#include "syntax/parser.h"

namespace sdfc {
namespace {

std::string where(const SourceRange& r) {
  if (!r.file) return "?";
  auto [line, col] = r.file->lineColumn(r.begin);
  return r.file->path + ":" + std::to_string(line) + ":" + std::to_string(col);
}

// Two spellings of one file ("a/../parts.sdf", "parts.sdf") are one file.
std::string identity(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : canonical.string();
}

class Loader {
 public:
  Loader(Diagnostics& diags, ImportSet& out) : diags_(diags), out_(out) {}

  // The imports of `file` (whose definitions live under `prefix`).
  void importsOf(const ast::File& file, const SourceFile& source, const std::string& prefix) {
    for (const ast::Statement& s : file.statements)
      if (s.is_import) importOne(s, source, prefix);
  }

  void enter(const SourceFile& main) { stack_.push_back({identity(main.path), main.path, nullptr}); }

 private:
  struct Frame {
    std::string id, path;
    const ast::Statement* import;
  };
  Diagnostics& diags_;
  ImportSet& out_;
  std::vector<Frame> stack_;  // the chain of files being imported, outermost first
  std::map<std::string, std::shared_ptr<SourceFile>> sources_;
  std::map<std::string, const ast::File*> trees_;
  std::set<std::pair<std::string, std::string>> bound_;  // (file, prefix) already brought in

  std::string chain(const std::string& last) const {
    std::string c;
    for (const Frame& f : stack_) c += "'" + f.path + "' -> ";
    return c + "'" + last + "'";
  }

  void importOne(const ast::Statement& s, const SourceFile& source, const std::string& prefix) {
    const std::string path = resolveBesides(source.path, s.import_path);
    const std::string id = identity(path);
    for (const Frame& f : stack_)
      if (f.id == id) {
        Diagnostic& d = diags_.error(s.import_path_range, "import cycle: " + chain(path));
        for (size_t i = 1; i < stack_.size(); ++i)
          d.notes.push_back({Severity::Note, stack_[i].import->import_path_range,
                             "'" + stack_[i].path + "' is imported here", {}});
        return;
      }
    if (static_cast<int>(stack_.size()) > kMaxImportDepth) {
      diags_.error(s.import_path_range, "imports are nested more than " + std::to_string(kMaxImportDepth) +
                                            " files deep: " + chain(path));
      return;
    }
    const std::string inner = prefix + (s.alias.empty() ? "" : s.alias + ".");
    const ast::File* tree = parsed(s, path, id);
    if (!tree) return;
    const SourceFile& file = *sources_[id];
    out_.edges[&source].push_back(&file);
    if (!bound_.insert({id, inner}).second) return;  // the same file into the same names: once
    const std::string via = "'" + path + "', imported at " + where(s.import_path_range);
    for (const ast::Statement& d : tree->statements)
      if (d.is_let) out_.definitions.push_back({&d, inner, via, &s});
    stack_.push_back({id, path, &s});
    importsOf(*tree, file, inner);
    stack_.pop_back();
  }

  // Reads and parses a file once, however often it is imported.
  const ast::File* parsed(const ast::Statement& s, const std::string& path, const std::string& id) {
    if (auto it = trees_.find(id); it != trees_.end()) return it->second;
    // Only regular files: a FIFO or a device (/dev/zero) would block or never end.
    std::error_code ec;
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec)) {
      diags_.error(s.import_path_range, "'" + path + "' is not a regular file");
      trees_[id] = nullptr;
      return nullptr;
    }
    std::unique_ptr<SourceFile> file = readSourceFile(path);
    if (!file) {
      diags_.error(s.import_path_range, "cannot read '" + path + "' (imports are relative to the importing file)");
      trees_[id] = nullptr;
      return nullptr;
    }
    std::shared_ptr<SourceFile> shared(std::move(file));
    sources_[id] = shared;
    out_.files.push_back(shared);
    auto tree = std::make_unique<ast::File>(parse(*shared, diags_));
    for (const ast::Statement& st : tree->statements)
      if (!st.is_let && !st.is_import && st.value && st.value->kind != ast::ExprKind::Error) {
        Diagnostic& d = diags_.error(st.range, "an imported file holds only 'let' definitions and imports; this "
                                               "belongs in the file that imports it");
        d.notes.push_back({Severity::Note, s.import_path_range, "'" + path + "' is imported here", {}});
      }
    const ast::File* raw = tree.get();
    out_.trees.push_back(std::move(tree));
    trees_[id] = raw;
    return raw;
  }
};

}  // namespace

ImportSet loadImports(const ast::File& file, const SourceFile& source, Diagnostics& diags) {
  ImportSet out;
  Loader loader(diags, out);
  loader.enter(source);
  loader.importsOf(file, source, "");
  return out;
}

}  // namespace sdfc
