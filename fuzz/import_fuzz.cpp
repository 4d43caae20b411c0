// libFuzzer target: imports. One input is a scene and up to four files it may
// import, cut at NUL bytes: the first part is main.sdf, the next 1.sdf to
// 4.sdf, all written into a folder of this process's own; main.sdf is then
// parsed and checked through the import machinery (check/imports.cpp: cycles,
// diamonds, aliases, nesting, clashes, non-definitions, files that are not
// there). Every input must end in diagnostics that point inside their files or
// a usable checked scene (fuzz/invariants.h), never a crash, hang or leak.
#include <sys/stat.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "driver/compile.h"
#include "fuzz/dispatch_input.h"
#include "fuzz/invariants.h"

namespace {

constexpr int kMaxFiles = 5;  // main.sdf and 1.sdf..4.sdf

struct Folder {
  std::string path = "/tmp/sdfc_import_fuzz_" + std::to_string(::getpid());
  Folder() { ::mkdir(path.c_str(), 0700); }
  ~Folder() {
    for (int i = 0; i < kMaxFiles; ++i) std::remove(file(i).c_str());
    ::rmdir(path.c_str());
  }
  std::string file(int i) const { return path + "/" + (i == 0 ? std::string("main") : std::to_string(i)) + ".sdf"; }
};

void put(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();  // the fuzzer cannot run without its folder
  if (!text.empty() && std::fwrite(text.data(), 1, text.size(), f) != text.size()) std::abort();
  std::fclose(f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Folder folder;
  const std::vector<std::string> parts = sdfc::fuzz::importParts(data, size, kMaxFiles);
  // A file the input does not give is absent (an import of it: "cannot read").
  for (int i = 0; i < kMaxFiles; ++i) {
    if (i < int(parts.size())) put(folder.file(i), parts[i]);
    else std::remove(folder.file(i).c_str());
  }
  sdfc::Diagnostics diags;
  sdfc::CompiledScene compiled = sdfc::checkSource(folder.file(0), parts[0], sdfc::CompileOptions{}, diags);
  (void)diags.format();
  (void)diags.formatJson();
  const std::string broken = sdfc::fuzz::violatedInvariant(compiled, diags, true);
  if (!broken.empty()) {
    std::fprintf(stderr, "sdfc_import_fuzz: invariant broken: %s\n", broken.c_str());
    std::abort();
  }
  return 0;
}
