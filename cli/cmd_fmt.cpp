// `sdfc fmt`: the canonical layout (compiler/format). Files in place with -w,
// a list of the files that would change with --check (exit 1), stdin to
// stdout with no file. A file with syntax errors is reported and left alone.
#include <algorithm>
#include <iostream>
#include <iterator>
#include <unistd.h>

#include "cli_support.h"
#include "commands.h"
#include "format/formatter.h"
#include "rewrite_file.h"

namespace sdfc {

int runFmt(const CommandLine& cl) {
  std::vector<std::string> inputs = cl.inputs;
  const bool from_stdin = inputs.empty();
  if (from_stdin) inputs.push_back("-");
  int exit_code = kExitOk;
  for (const std::string& path : inputs) {
    std::unique_ptr<SourceFile> source;
    if (path == "-") {
      std::string text((std::istreambuf_iterator<char>(std::cin)), std::istreambuf_iterator<char>());
      source = std::make_unique<SourceFile>("<stdin>", std::move(text));
    } else {
      source = readSourceFile(path);
      if (!source) {
        const std::string why = sourceFileProblem(path);
        std::cerr << "sdfc: error: cannot read '" << path << "'" << (why.empty() ? "" : ": " + why) << "\n";
        exit_code = std::max(exit_code, kExitIo);
        continue;
      }
    }
    Diagnostics diags;
    const std::optional<std::string> formatted = formatSource(*source, diags);
    if (!formatted) {
      std::cerr << diags.format(isatty(2));
      exit_code = std::max(exit_code, kExitScene);
      continue;
    }
    const bool changed = *formatted != source->text;
    if (cl.check_format) {
      if (changed) {
        std::cout << source->path << "\n";
        exit_code = std::max(exit_code, kExitScene);
      }
    } else if (cl.write_in_place && path != "-") {
      // Not writeFileAtomically: a rename over `path` would turn a symlink
      // into a plain file, split hard links and reset the mode.
      try {
        if (changed) rewriteFileKeepingIdentity(path, *formatted);
      } catch (const FileWriteError& e) {  // the other files are still formatted
        std::cerr << "sdfc: error: " << e.what() << "\n";
        exit_code = std::max(exit_code, kExitIo);
      }
    } else {
      std::cout << *formatted;
    }
  }
  return exit_code;
}

}  // namespace sdfc
