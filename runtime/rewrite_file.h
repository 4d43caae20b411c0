// Rewriting a file the user owns and edits (`sdfc fmt -w`): the new text goes
// where the old one was, and everything else that identifies the file stays.
#pragma once
#include <string>
#include <string_view>

namespace sdfc {

// Replaces the contents of the existing regular file at `path` with `bytes`:
// - a symbolic link (or a chain of them) stays a link: its target is written;
// - the mode, the owner and every hard link are kept;
// - a file with one link goes through a temporary beside the target that is
//   written, fsynced and renamed over it (given the old mode and owner first),
//   so an interrupted run leaves the old text or the new, never a mix;
// - a file with several hard links (or whose owner or directory a rename
//   cannot keep) is written in place: see the comment in rewrite_file.cpp.
// Throws FileWriteError (atomic_file.h) naming the path and the reason.
void rewriteFileKeepingIdentity(const std::string& path, std::string_view bytes);

}  // namespace sdfc
