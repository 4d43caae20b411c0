// sdfc: one binary, subcommands in the spirit of glslc and pbrt.
//   sdfc check scene.sdf            diagnostics only
//   sdfc compile scene.sdf -o out   GLSL / SPIR-V / IR
//   sdfc render scene.sdf -o x.png  path-traced image (or a debug view)
//   sdfc view scene.sdf             live window, reloads on save
//   sdfc eval scene.sdf             float64 distances at points from stdin
//   sdfc mesh scene.sdf -o x.glb    triangle mesh export
//   sdfc devices                    list Vulkan devices
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>

#include "commands.h"
#include "usage_errors.h"
#include "driver_select.h"
#include "stage_timings.h"
#include "vk_check.h"

extern const char* const kSdfcRevision;  // revision.cpp, written at build time

int main(int argc, char** argv) {
  using namespace sdfc;
  markMainEntered();  // --timings' process start to main
  CLI::App app{"sdfc: a compiler and path tracer for signed-distance scenes"};
  // The version line also names the Vulkan driver a render would use by default
  // (SDFC_DRIVER or auto; --driver on the same command line is not seen here).
  app.set_version_flag("--version", [] {
    std::string driver;
    try {
      driver = selectedDriver().reason;
    } catch (const RuntimeError& e) {  // SDFC_LAVAPIPE naming nothing
      driver = std::string("error: ") + e.what();
    }
    return std::string("sdfc ") + kSdfcVersion + "\ncommit: " + kSdfcRevision + "\ndriver: " + driver;
  });
  app.require_subcommand(1);
  // Accepted before or after the subcommand (fallthrough hands it up to here).
  std::string driver = "auto";
  app.add_option("--driver", driver,
                 "Vulkan driver: auto (the bundled Mesa 25 lavapipe when present), system, bundled")
      ->check(CLI::IsMember({"auto", "system", "bundled"}))
      ->envname("SDFC_DRIVER");
  app.fallthrough();
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
    std::cerr << "sdfc: error: " << usageErrorText(app, e, argc, argv) << "\n";
    return kExitUsage;
  }
  try {
    DriverChoice choice = DriverChoice::Auto;
    parseDriverChoice(driver, choice);
    // An explicit choice is applied now (and an absent bundled driver reported
    // before any work); child processes such as farm shards inherit it. Auto is
    // applied lazily by the first Vulkan call, so `sdfc check` loads nothing.
    if (choice != DriverChoice::Auto) {
      setenv("SDFC_DRIVER", driverChoiceName(choice), 1);
      selectDriver(choice);
    }
    if (cl.command == "view") {
      selectedDriver();  // before GLFW's first Vulkan loader call
      return runView(cl);
    }
    return runCommand(cl);
  } catch (const RuntimeError& e) {
    std::cerr << "sdfc: error: device: " << e.what() << "\n";
    return kExitDevice;
  } catch (const std::exception& e) {
    std::cerr << "sdfc: error: " << e.what() << "\n";
    return kExitIo;
  }
}
