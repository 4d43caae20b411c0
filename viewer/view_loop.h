// `sdfc view`: the frame loop. Each frame: poll input (or run the script), poll the
// file, swap in a finished background build, draw one progressive pass with the
// shared Renderer (dynamic resolution while the camera moves), tone-map exactly as
// the PNG writer does and present.
#pragma once
#include "commands.h"

namespace sdfc::view {

// Exit codes as the other commands: 0 on quit, 3 without a display or on a device
// failure (or any validation message when validation is on), 2 for a bad script.
int runView(const CommandLine& command_line);

}  // namespace sdfc::view
