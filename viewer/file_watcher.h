// Notices when a file is saved: polls its modification time (nanoseconds), size
// and inode once a frame. Polling a stat is a few microseconds and sees both
// in-place writes and editors that save to a temporary and rename it over.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace sdfc::view {

class FileWatcher {
 public:
  explicit FileWatcher(std::string path);
  // True once per change since the last call (the first call records the state).
  bool changed();
  // Watch these files too (the scene's imports, as of its last compile);
  // a file already watched keeps its stamp, so a save during a compile counts.
  void watchAlso(const std::vector<std::string>& paths);

 private:
  struct Stamp {
    int64_t mtime_ns = -1, size = -1;
    uint64_t inode = 0;
    bool operator==(const Stamp& o) const {
      return mtime_ns == o.mtime_ns && size == o.size && inode == o.inode;
    }
  };
  static Stamp read(const std::string& path);

  std::string path_;
  Stamp last_;
  std::map<std::string, Stamp> also_;
};

}  // namespace sdfc::view
