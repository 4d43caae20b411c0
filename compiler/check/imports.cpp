#include "check/imports.h"

#include <algorithm>
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

  void enter(const SourceFile& main) {
    stack_.push_back({identity(main.path), main.path, nullptr});
    bytes_ = main.text.size();
  }

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
  std::map<std::string, std::string> bound_;  // file -> the prefix its definitions are bound under
  std::uintmax_t bytes_ = 0;                  // the scene's and its imports' text read so far

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
    // Each file is bound (and its imports followed) once; reached again
    // under other names, those are an alias for the first.
    const auto [first, inserted] = bound_.try_emplace(id, inner);
    if (!inserted) {
      if (first->second == inner) return;  // the same file into the same names: once
      std::vector<std::string>& to = out_.aliases[inner];
      if (std::find(to.begin(), to.end(), first->second) == to.end()) {
        to.push_back(first->second);
        out_.alias_list.push_back({inner, first->second, &s,
                                   "'" + path + "', imported at " + where(s.import_path_range)});
      }
      return;
    }
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
    // The scene file's own rule (diag/source.h), before a byte is read: only
    // regular files (a FIFO or a device such as /dev/zero would block or never
    // end), none over kMaxSourceBytes, and the scene and everything it imports
    // together within kMaxSourceBytes too (a 300 MB import ran out of memory
    // with no file or line).
    const std::string problem = sourceFileProblem(path);
    if (!problem.empty()) {
      diags_.error(s.import_path_range, "cannot import '" + path + "': " + problem);
      trees_[id] = nullptr;
      return nullptr;
    }
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (!ec && size > kMaxSourceBytes - std::min(bytes_, kMaxSourceBytes)) {
      diags_.error(s.import_path_range,
                   "cannot import '" + path + "': it is " + std::to_string(size >> 20) +
                       " MiB, and with the " + std::to_string(bytes_ >> 20) +
                       " MiB already read the scene and its imports would be more than " +
                       std::to_string(kMaxSourceBytes >> 20) + " MiB");
      trees_[id] = nullptr;
      return nullptr;
    }
    std::unique_ptr<SourceFile> file = readSourceFile(path);
    if (!file) {
      diags_.error(s.import_path_range, "cannot read '" + path + "' (imports are relative to the importing file)");
      trees_[id] = nullptr;
      return nullptr;
    }
    bytes_ += file->text.size();
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

std::string resolveImportedKey(const std::map<std::string, std::vector<std::string>>& aliases,
                               const std::string& key, size_t inside,
                               const std::function<bool(const std::string&)>& bound) {
  if (bound(key)) return key;
  // (key, length of the namespace it is in): after a rewrite to "x.", only
  // aliases inside "x." apply (an alias of "" is main's, and re-applying it
  // to "x.foo" would wander through every string of prefixes).
  std::set<std::pair<std::string, size_t>> tried = {{key, inside}};
  std::vector<std::pair<std::string, size_t>> stack = {{key, inside}};
  while (!stack.empty()) {
    const auto [k, within] = stack.back();
    stack.pop_back();
    // Every prefix of k that ends at a '.' ("", "a.", "a.b."), within its namespace, longest first.
    std::vector<size_t> ends = {within};
    for (size_t dot = k.find('.', within); dot != std::string::npos; dot = k.find('.', dot + 1)) ends.push_back(dot + 1);
    for (auto end = ends.rbegin(); end != ends.rend(); ++end) {
      const auto a = aliases.find(k.substr(0, *end));
      if (a == aliases.end()) continue;
      for (const std::string& to : a->second) {
        std::pair<std::string, size_t> next{to + k.substr(*end), to.size()};
        if (!tried.insert(next).second) continue;
        if (bound(next.first)) return next.first;
        stack.push_back(std::move(next));
      }
    }
  }
  return "";
}

ImportSet loadImports(const ast::File& file, const SourceFile& source, Diagnostics& diags) {
  ImportSet out;
  Loader loader(diags, out);
  loader.enter(source);
  loader.importsOf(file, source, "");
  return out;
}

}  // namespace sdfc
