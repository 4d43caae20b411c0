#include "rewrite_file.h"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <vector>

#include "atomic_file.h"

namespace sdfc {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw FileWriteError("cannot write '" + path + "': " + why);
}

bool pwriteAll(int fd, std::string_view bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd, bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      return false;
    }
    done += static_cast<size_t>(n);
  }
  return true;
}

bool preadAll(int fd, std::string& out) {
  out.clear();
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::pread(fd, buffer, sizeof buffer, static_cast<off_t>(out.size()));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    if (n == 0) return true;
    out.append(buffer, static_cast<size_t>(n));
  }
}

// Temporary, fsync, rename: false (nothing changed) when the rename could not
// keep the file's owner or the directory does not let us create the temporary.
bool replaceByRename(const std::string& target, const struct stat& st, std::string_view bytes) {
  const size_t slash = target.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : target.substr(0, slash);
  const std::string base = slash == std::string::npos ? target : target.substr(slash + 1);
  std::string pattern = dir + "/." + base + ".XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) return false;
  const std::string temporary(name.data());
  auto give_up = [&] {
    ::close(fd);
    ::unlink(temporary.c_str());
  };
  // The owner first (only root or the owner itself can keep it), then the
  // mode, which chown may have cleared set-id bits of.
  if ((st.st_uid != ::geteuid() || st.st_gid != ::getegid()) && ::fchown(fd, st.st_uid, st.st_gid) != 0) {
    give_up();
    return false;
  }
  if (::fchmod(fd, st.st_mode & 07777) != 0) {
    give_up();
    return false;
  }
  if (!pwriteAll(fd, bytes) || ::fsync(fd) != 0) {
    const int error = errno;
    give_up();
    fail(target, std::strerror(error));
  }
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    fail(target, std::strerror(error));
  }
  if (::rename(temporary.c_str(), target.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    fail(target, std::strerror(error));
  }
  return true;
}

// Hard links share one inode, and a rename would give `target` a new one:
// the other names would keep the old text. So the new text is written into
// the inode itself. Why this is safe enough: the whole new text is ready in
// memory before the file is touched; the current text is read back first, and
// when a write fails (a full disk while the file grows) it is written back and
// the file cut to its old size (those blocks were already the file's, so the
// restore needs no new space); the file is fsynced before we report success.
// What remains is a crash during the one pwrite of a scene file's few
// kilobytes, which a rename would avoid only by splitting the links.
void replaceInPlace(const std::string& target, std::string_view bytes) {
  const int fd = ::open(target.c_str(), O_RDWR | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) fail(target, std::strerror(errno));
  std::string old;
  if (!preadAll(fd, old)) {
    const int error = errno;
    ::close(fd);
    fail(target, std::strerror(error));
  }
  if (!pwriteAll(fd, bytes) || ::ftruncate(fd, static_cast<off_t>(bytes.size())) != 0 || ::fsync(fd) != 0) {
    const int error = errno;
    const bool restored = pwriteAll(fd, old) && ::ftruncate(fd, static_cast<off_t>(old.size())) == 0;
    ::close(fd);
    fail(target, std::string(std::strerror(error)) +
                     (restored ? " (the file keeps its old text)" : " (the file may be damaged)"));
  }
  if (::close(fd) != 0) fail(target, std::strerror(errno));
}

}  // namespace

void rewriteFileKeepingIdentity(const std::string& path, std::string_view bytes) {
  char resolved[PATH_MAX];
  if (!::realpath(path.c_str(), resolved)) fail(path, std::strerror(errno));
  const std::string target(resolved);
  struct stat st;
  if (::stat(target.c_str(), &st) != 0) fail(path, std::strerror(errno));
  if (!S_ISREG(st.st_mode)) fail(path, "not a regular file");
  if (::access(target.c_str(), W_OK) != 0) fail(path, std::strerror(errno));
  if (st.st_nlink == 1 && replaceByRename(target, st, bytes)) return;
  replaceInPlace(target, bytes);
}

}  // namespace sdfc
