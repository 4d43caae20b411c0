#include "file_watcher.h"

#include <sys/stat.h>

#include <utility>

namespace sdfc::view {

FileWatcher::FileWatcher(std::string path) : path_(std::move(path)), last_(read()) {}

FileWatcher::Stamp FileWatcher::read() const {
  struct stat st {};
  Stamp stamp;
  if (stat(path_.c_str(), &st) != 0) return stamp;  // missing (mid-rename): not a change yet
  stamp.mtime_ns = int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  stamp.size = st.st_size;
  stamp.inode = st.st_ino;
  return stamp;
}

bool FileWatcher::changed() {
  const Stamp now = read();
  if (now.mtime_ns < 0 || now == last_) return false;
  last_ = now;
  return true;
}

}  // namespace sdfc::view
