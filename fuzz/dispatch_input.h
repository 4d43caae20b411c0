// The inputs of the import and language-server dispatch fuzz targets, shared
// with tests/fuzz_seeds_test.cpp, which replays their seeds in the normal run.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sdfc::fuzz {

// sdfc_import_fuzz: the scene (main.sdf) and the files 1.sdf.. it may import,
// cut at NUL bytes (at most `max_files` parts; later NULs stay in the last).
inline std::vector<std::string> importParts(const std::uint8_t* data, std::size_t size, std::size_t max_files) {
  std::vector<std::string> parts(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == 0 && parts.size() < max_files) parts.emplace_back();
    else parts.back() += char(data[i]);
  }
  return parts;
}

inline std::string lspFrame(const std::string& body) {
  return "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
}

// sdfc_lsp_dispatch_fuzz: what the server reads for an input of message
// bodies, one a line: initialize, the opening of kDispatchUri, each line
// framed, then shutdown and exit.
inline constexpr const char* kDispatchUri = "file:///sdfc_lsp_fuzz/s.sdf";
inline std::string dispatchStream(const std::string& lines) {
  std::string in =
      lspFrame(R"({"jsonrpc":"2.0","id":0,"method":"initialize","params":{"capabilities":{}}})") +
      lspFrame(std::string(R"({"jsonrpc":"2.0","method":"textDocument/didOpen","params":{"textDocument":)") +
               R"({"uri":")" + kDispatchUri + R"(","languageId":"sdf","version":1,)" +
               R"("text":"let r = 1\nlet f(x, y: 2) = sphere(radius: x * y)\nscene { f(r) box(size: 1) }\n"}}})");
  for (std::size_t begin = 0; begin <= lines.size();) {
    std::size_t end = lines.find('\n', begin);
    if (end == std::string::npos) end = lines.size();
    if (end > begin) in += lspFrame(lines.substr(begin, end - begin));
    begin = end + 1;
  }
  return in + lspFrame(R"({"jsonrpc":"2.0","id":"last","method":"shutdown"})") +
         lspFrame(R"({"jsonrpc":"2.0","method":"exit"})");
}

}  // namespace sdfc::fuzz
