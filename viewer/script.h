// Scripted input for tests and benchmarks (`sdfc view --script events.txt`): one
// command a line, run between frames through the same handlers as the mouse and
// keyboard. docs/view.md lists the commands.
#pragma once
#include <string>
#include <vector>

namespace sdfc::view {

struct ScriptCommand {
  std::string verb;
  std::vector<std::string> args;
  std::string rest;  // the text after the verb (for `run`)
  int line = 0;
};

// Throws std::runtime_error("path:line: error: ...") on an unknown command or
// wrong arguments, before the window opens.
std::vector<ScriptCommand> loadScript(const std::string& path);

// GLFW key code for a script key name ("1", "f", "space", "escape", "period", ...),
// -1 when unknown.
int keyCodeForName(const std::string& name);

}  // namespace sdfc::view
