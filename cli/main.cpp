// sdfc: one binary, subcommands in the spirit of glslc and pbrt.
//   sdfc check scene.sdf            diagnostics only
//   sdfc compile scene.sdf -o out   GLSL / SPIR-V / IR
//   sdfc render scene.sdf -o x.png  path-traced image (or a debug view)
//   sdfc view scene.sdf             live window, reloads on save
//   sdfc eval scene.sdf             float64 distances at points from stdin
//   sdfc mesh scene.sdf -o x.glb    triangle mesh export
//   sdfc devices                    list Vulkan devices
#include <CLI/CLI.hpp>
#include <iostream>

#include "commands.h"
#include "view_loop.h"
#include "vk_check.h"

int main(int argc, char** argv) {
  using namespace sdfc;
  CLI::App app{"sdfc: a compiler and path tracer for signed-distance scenes"};
  app.set_version_flag("--version", std::string("sdfc ") + kSdfcVersion);
  app.require_subcommand(1);
  CommandLine cl;
  registerCommands(app, cl);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }
  try {
    if (cl.command == "view") return view::runView(cl);
    return runCommand(cl);
  } catch (const RuntimeError& e) {
    std::cerr << "sdfc: error: device: " << e.what() << "\n";
    return kExitDevice;
  } catch (const std::exception& e) {
    std::cerr << "sdfc: error: " << e.what() << "\n";
    return kExitIo;
  }
}
