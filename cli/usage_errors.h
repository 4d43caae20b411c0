// The text of a command-line error (after "sdfc: error: "), with a
// suggestion where a subcommand or an option was mistyped.
#pragma once
#include <CLI/CLI.hpp>
#include <string>

namespace sdfc {

std::string usageErrorText(const CLI::App& app, const CLI::ParseError& error, int argc, char** argv);

}  // namespace sdfc
