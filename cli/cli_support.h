// What every subcommand shares: loading a scene with -D overrides, printing
// its diagnostics, and writing files through a temporary name.
#pragma once
#include <string>

#include "commands.h"
#include "driver/compile.h"

namespace sdfc {

struct LoadedScene {
  CompiledScene compiled;
  int exit_code = kExitOk;
};

// Options for the compiler from the command line's flags.
CompileOptions compileOptionsFrom(const CommandLine& cl);

// Reads, checks and (with `emit`) compiles cl.input, printing diagnostics to
// stderr in cl.diagnostics_format. exit_code is kExitScene on errors (or on
// warnings with --Werror), kExitIo when the file cannot be read.
LoadedScene loadScene(const CommandLine& cl, Diagnostics& diags, bool emit, bool spirv = true,
                      CompileOptions options = {}, bool options_given = false);

// Writes `bytes` to `path` via "<path>.tmp" and a rename.
void writeFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace sdfc
