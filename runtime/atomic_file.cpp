#include "atomic_file.h"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <vector>

namespace sdfc {
namespace {

std::string reason(int error) { return std::strerror(error); }

[[noreturn]] void fail(const std::string& path, int error) {
  throw FileWriteError("cannot write '" + path + "': " + reason(error));
}

// write(2) until every byte is out; false with errno set on failure.
bool writeAll(int fd, std::string_view bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (n == 0) {
      errno = EIO;
      return false;
    }
    done += static_cast<size_t>(n);
  }
  return true;
}

std::string directoryOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string baseNameOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

bool isStreamMode(mode_t mode) { return S_ISFIFO(mode) || S_ISCHR(mode) || S_ISBLK(mode) || S_ISSOCK(mode); }

}  // namespace

bool isStreamPath(const std::string& path) {
  if (path == "-") return true;
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && isStreamMode(st.st_mode);
}

void checkWritablePath(const std::string& path) {
  if (path.empty()) throw FileWriteError("no output path given");
  if (isStreamPath(path)) return;
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw FileWriteError("cannot write '" + path + "': it is a directory");
  const std::string dir = directoryOf(path);
  if (::stat(dir.c_str(), &st) != 0) {
    // sdfc creates no folders (a mistyped -o would leave one behind): say which is missing.
    if (errno == ENOENT)
      throw FileWriteError("cannot write '" + path + "': the folder '" + dir +
                           "' does not exist (sdfc creates no folders: mkdir -p '" + dir + "' first)");
    throw FileWriteError("cannot write '" + path + "': directory '" + dir + "': " + reason(errno));
  }
  if (!S_ISDIR(st.st_mode))
    throw FileWriteError("cannot write '" + path + "': '" + dir + "' is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw FileWriteError("cannot write '" + path + "': directory '" + dir + "': " + reason(errno));
}

void writeFileAtomically(const std::string& path, std::string_view bytes) {
  if (path == "-") {
    if (!writeAll(STDOUT_FILENO, bytes)) fail("standard output", errno);
    return;
  }
  if (isStreamPath(path)) {
    // Opened without O_CREAT or O_TRUNC: a FIFO or device is written as it is.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) fail(path, errno);
    const bool ok = writeAll(fd, bytes);
    const int error = errno;
    if (::close(fd) != 0 && ok) fail(path, errno);
    if (!ok) fail(path, error);
    return;
  }
  checkWritablePath(path);
  // ".name.XXXXXX.tmp" beside the target: the rename stays within one file
  // system, and the random part is unique per writer.
  std::string pattern = directoryOf(path) + "/." + baseNameOf(path) + ".XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) fail(path, errno);
  const std::string temporary(name.data());
  auto abandon = [&](int error) {
    ::unlink(temporary.c_str());
    fail(path, error);
  };
  // mkstemp creates 0600; give the file the usual permissions (umask applies).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  if (::fchmod(fd, 0666 & ~mask) != 0) {
    const int error = errno;
    ::close(fd);
    abandon(error);
  }
  if (!writeAll(fd, bytes) || ::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    abandon(error);
  }
  if (::close(fd) != 0) abandon(errno);
  if (::rename(temporary.c_str(), path.c_str()) != 0) abandon(errno);
}

}  // namespace sdfc
