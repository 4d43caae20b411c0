// What every subcommand shares: loading a scene with -D overrides, printing
// its diagnostics, and writing files through a temporary name.
#pragma once
#include <optional>
#include <string>

#include "api/option_limits.h"
#include "api/scene.h"
#include "atomic_file.h"
#include "commands.h"
#include "driver/compile.h"
#include "scene_render.h"

namespace sdfc {

struct LoadedScene {
  CompiledScene compiled;
  int exit_code = kExitOk;
  std::unique_ptr<api::Scene> keep;  // what `compiled`'s diagnostics point into
};

// True after printing `sdfc: error:` when writing `output` would overwrite a
// file the scene was read from: the scene, its imports or its data files
// (textures, maps, meshes, point files). Compared by file identity (st_dev,
// st_ino), so another spelling, a hard link or a symlink is the same file.
bool outputIsAnInput(const std::string& output, const std::string& scene_path, const CompiledScene& c);

// Options for the compiler from the command line's flags.
CompileOptions compileOptionsFrom(const CommandLine& cl);

// -D and -W flags into `load` (defines, disabled warnings, werror); prints the
// usage error and returns kExitUsage for a bad one.
int loadOptionsFrom(const CommandLine& cl, api::LoadOptions& load);

// Reads, checks and (with `emit`) compiles cl.input through api::loadFile, printing diagnostics to
// stderr in cl.diagnostics_format. exit_code is kExitScene on errors (or on
// warnings with --Werror), kExitIo when the file cannot be read.
LoadedScene loadScene(const CommandLine& cl, Diagnostics& diags, bool emit, bool spirv = true,
                      CompileOptions options = {}, bool options_given = false);


// A number as the language writes one, with an optional sign: digits, an
// optional fraction and exponent ("-1.5e3"). No hex, "inf" or "nan", and
// the value must be finite in float32 (the shader's precision).
std::optional<double> parsePlainNumber(const std::string& text);

// The check of a floating-point flag: a plain number (as parsePlainNumber)
// within [lo, hi] (above lo when open_low). CLI::Range alone lets "nan"
// through, since every comparison with NaN is false.
CLI::Validator numberIn(double lo, double hi, bool open_low = false);
// A whole-number option: plain decimal digits within [lo, hi] (not 1.5, 1e3, inf).
CLI::Validator wholeNumberIn(long long lo, long long hi);
// The check of a flag the Python package and the viewer take too, from the
// one table of their ranges (api/option_limits.h): wholeNumberIn or numberIn.
CLI::Validator limitOf(api::Option option);

// Usage checks shared by render, view, eval, mesh and farm submit: --time must be a float32
// number. Prints the error and returns false when it is not.
bool checkTimeOption(double time, const char* option = "--time");

// The render settings the command line overrides (--size, --spp, --bounces,
// --light-samples, --seed, --time), shared by render, export and the farm;
// false after printing a usage error (a bad --size or --time).
bool renderOverridesFrom(const CommandLine& cl, RenderOverrides& o);

// -o's image extension (.png, .exr, .pfm): prints a usage error and returns
// false for any other.
bool checkImageExtension(const std::string& path);

// Reads the scene file; on failure prints why (missing, unreadable, a
// directory) and returns nullptr.
std::unique_ptr<SourceFile> readSceneFile(const std::string& path);

}  // namespace sdfc
