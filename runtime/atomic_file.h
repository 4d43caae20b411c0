// Writing output files so that a failed or interrupted run never leaves a
// half-written file at the path, and two runs writing one path never mix.
// Every image, shader and mesh sdfc writes goes through here.
#pragma once
#include <stdexcept>
#include <string>
#include <string_view>

namespace sdfc {

// A file that cannot be written (exit code 4 on the command line).
class FileWriteError : public std::runtime_error {
 public:
  explicit FileWriteError(const std::string& message) : std::runtime_error(message) {}
};

// Writes `bytes` to `path`:
// - "-" is standard output;
// - a FIFO, character or block device (e.g. /dev/null, /dev/stdout) is
//   opened and written in place: renaming over it would replace the node;
// - anything else goes to a unique temporary in the same directory
//   (mkstemp: concurrent writers never share one, and a stale one left by
//   SIGKILL is never reused), every write, the fsync and the close are
//   checked, and only then is it renamed over `path`. On failure the
//   temporary is removed and the previous file at `path` is untouched.
// Throws FileWriteError naming the path and the system's reason.
void writeFileAtomically(const std::string& path, std::string_view bytes);

// Before any long work: throws FileWriteError when `path` could not be
// written later (its directory is missing or not writable, or it is a
// directory). "-" and existing FIFOs/devices pass.
void checkWritablePath(const std::string& path);

// True for "-" and for existing FIFOs and device nodes: outputs written in
// place rather than through a temporary and a rename.
bool isStreamPath(const std::string& path);

}  // namespace sdfc
