#pragma once
namespace sdfc::lsp { int runStdioServer(); }
