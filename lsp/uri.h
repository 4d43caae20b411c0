// file: URIs -> file system paths (RFC 8089, RFC 3986 percent-encoding), so a
// document's `file("towers.csv")` is read beside the document, as `sdfc check`
// reads it beside the scene. Replies name a document by the URI the client
// sent, byte for byte, so nothing is encoded back.
#pragma once
#include <optional>
#include <string>

namespace sdfc::lsp {

// The local path of a file: URI ("file:///a%20b/s.sdf", "file://localhost/...",
// "file:/..."), percent-decoded; nullopt for other schemes (untitled:, a remote
// host) and for a path that would hold a NUL byte.
std::optional<std::string> pathFromUri(const std::string& uri);

}  // namespace sdfc::lsp
