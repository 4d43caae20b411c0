#include "file_watcher.h"

#include <sys/stat.h>

#include <utility>

namespace sdfc::view {

FileWatcher::FileWatcher(std::string path) : path_(std::move(path)), last_(read(path_)) {}

FileWatcher::Stamp FileWatcher::read(const std::string& path) {
  struct stat st {};
  Stamp stamp;
  if (stat(path.c_str(), &st) != 0) return stamp;  // missing (mid-rename): not a change yet
  stamp.mtime_ns = int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  stamp.size = st.st_size;
  stamp.inode = st.st_ino;
  return stamp;
}

bool FileWatcher::changed() {
  bool any = false;
  const Stamp now = read(path_);
  if (now.mtime_ns >= 0 && !(now == last_)) {
    last_ = now;
    any = true;
  }
  for (auto& [path, last] : also_) {
    const Stamp stamp = read(path);
    if (stamp.mtime_ns < 0 || stamp == last) continue;
    last = stamp;
    any = true;
  }
  return any;
}

void FileWatcher::watchAlso(const std::vector<std::string>& paths) {
  std::map<std::string, Stamp> next;
  for (const std::string& p : paths) {
    auto it = also_.find(p);
    next[p] = it != also_.end() ? it->second : read(p);
  }
  also_ = std::move(next);
}

}  // namespace sdfc::view
