// The readers of data files (meshes, images, point lists) take a path and
// choose the format by its extension: a fuzz input is written to a file of
// this process's own under /tmp once per extension tried, removed at exit.
#pragma once
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>

namespace sdfc::fuzz {

struct ScratchFiles {
  std::set<std::string> paths;
  ~ScratchFiles() {
    for (const std::string& p : paths) std::remove(p.c_str());
  }
};

inline std::string writeInput(const std::uint8_t* data, std::size_t size, const char* extension) {
  static ScratchFiles scratch;
  const std::string path = "/tmp/sdfc_fuzz_" + std::to_string(::getpid()) + "." + extension;
  scratch.paths.insert(path);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();  // the fuzzer cannot run without its scratch file
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

}  // namespace sdfc::fuzz
