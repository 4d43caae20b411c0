// The Vulkan driver choice (runtime/driver_select.h): the bundled Mesa 25
// lavapipe by default when tools/setup.sh fetched it, the system's on request,
// and `sdfc devices` saying which one a command gets.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <sys/wait.h>
#include <unistd.h>
#include <string>

#include "driver_select.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

// stdout and exit status of a shell command.
std::string runCommand(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[512];
  while (size_t n = std::fread(buffer, 1, sizeof(buffer), pipe)) out.append(buffer, n);
  status = pclose(pipe);
  return out;
}

const std::string kSdfc = std::string(SDFC_BINARY_DIR) + "/cli/sdfc";

TEST(DriverSelect, ParsesTheThreeChoices) {
  DriverChoice choice = DriverChoice::Bundled;
  ASSERT_TRUE(parseDriverChoice("auto", choice));
  EXPECT_EQ(choice, DriverChoice::Auto);
  ASSERT_TRUE(parseDriverChoice("system", choice));
  EXPECT_EQ(choice, DriverChoice::System);
  ASSERT_TRUE(parseDriverChoice("bundled", choice));
  EXPECT_EQ(choice, DriverChoice::Bundled);
  EXPECT_FALSE(parseDriverChoice("mesa25", choice));
  EXPECT_EQ(choice, DriverChoice::Bundled);  // unchanged on failure
  EXPECT_STREQ(driverChoiceName(DriverChoice::System), "system");
}

// This process's device runs on the driver the selection reports: Mesa 25's
// lavapipe when bundled, the system's otherwise (CI runs this binary both ways
// through SDFC_DRIVER).
TEST(DriverSelect, ContextUsesTheSelectedDriver) {
  VulkanContext context;
  createContext(context);
  const DriverSelection& s = selectedDriver();
  const std::string driver = driverText(context.physical_device);
  std::printf("[ driver   ] %s: %s, %s\n", s.reason.c_str(), context.deviceName().c_str(),
              driver.c_str());
  if (s.bundled) {
    EXPECT_EQ(driver.rfind("Mesa 25.", 0), 0u) << driver;
    EXPECT_FALSE(s.icd.empty());
  } else if (context.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    EXPECT_NE(driver.rfind("Mesa 25.", 0), 0u) << driver;
  }
  destroyContext(context);
}

// The command line: `--driver system` and `--driver bundled` reach two different
// lavapipes when the bundled one is there; a bad value is a usage error.
TEST(DriverSelect, CommandLineReportsAndOverrides) {
  int status = 0;
  const std::string env = "env -u VK_DRIVER_FILES -u VK_ICD_FILENAMES -u SDFC_DRIVER ";
  const std::string system = runCommand(env + kSdfc + " --driver system devices", status);
  EXPECT_EQ(status, 0);
  EXPECT_NE(system.find("driver: system drivers (--driver system)"), std::string::npos) << system;
  const std::string by_default = runCommand(env + kSdfc + " devices", status);
  EXPECT_EQ(status, 0);
  const std::string version = runCommand(env + kSdfc + " --version", status);
  EXPECT_EQ(status, 0);
  EXPECT_NE(version.find("driver: "), std::string::npos) << version;
  if (bundledDriverManifest().empty()) {
    EXPECT_NE(by_default.find("no bundled lavapipe"), std::string::npos) << by_default;
    runCommand(env + kSdfc + " devices --driver bundled 2>/dev/null", status);
    EXPECT_NE(status, 0);
  } else {
    EXPECT_NE(by_default.find("bundled lavapipe (default when present)"), std::string::npos)
        << by_default;
    EXPECT_NE(by_default.find("Mesa 25."), std::string::npos) << by_default;
    EXPECT_EQ(system.find("Mesa 25."), std::string::npos) << system;
    // After the subcommand too, and the user's loader variables win over auto.
    const std::string bundled = runCommand(env + kSdfc + " devices --driver bundled", status);
    EXPECT_EQ(status, 0);
    EXPECT_NE(bundled.find("Mesa 25."), std::string::npos) << bundled;
    const std::string user = runCommand(
        "env -u SDFC_DRIVER VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json " + kSdfc +
            " devices",
        status);
    EXPECT_EQ(status, 0);
    EXPECT_NE(user.find("set by the user"), std::string::npos) << user;
    EXPECT_EQ(user.find("Mesa 25."), std::string::npos) << user;
  }
  runCommand(env + kSdfc + " --driver mesa25 devices 2>/dev/null", status);
  EXPECT_NE(status, 0);
}

// SDFC_LAVAPIPE names the lavapipe to use (a folder or its manifest), as an
// installed Python package does; a name that holds none is an error, never a
// silent fall back to the system's driver.
TEST(DriverSelect, SdfcLavapipeNamesTheDriver) {
  int status = 0;
  const std::string env = "env -u VK_DRIVER_FILES -u VK_ICD_FILENAMES -u SDFC_DRIVER ";
  const std::string missing =
      runCommand(env + "SDFC_LAVAPIPE=/nonexistent/lvp " + kSdfc + " devices 2>&1", status);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 3) << status << missing;  // kExitDevice
  EXPECT_NE(missing.find("SDFC_LAVAPIPE=/nonexistent/lvp: no lavapipe there"), std::string::npos)
      << missing;
  const std::string version =
      runCommand(env + "SDFC_LAVAPIPE=/nonexistent/lvp " + kSdfc + " --version", status);
  EXPECT_EQ(status, 0);
  EXPECT_NE(version.find("driver: error: SDFC_LAVAPIPE"), std::string::npos) << version;
  // --driver system wins: the variable names where a bundled driver is, not which to use.
  runCommand(env + "SDFC_LAVAPIPE=/nonexistent/lvp " + kSdfc + " --driver system devices", status);
  EXPECT_EQ(status, 0);
  const std::string manifest = bundledDriverManifest();
  if (manifest.empty()) GTEST_SKIP() << "no bundled lavapipe";
  const std::string folder = manifest.substr(0, manifest.rfind('/'));
  for (const std::string& named : {folder, manifest}) {
    const std::string out =
        runCommand(env + "SDFC_LAVAPIPE='" + named + "' " + kSdfc + " devices", status);
    EXPECT_EQ(status, 0);
    EXPECT_NE(out.find("bundled lavapipe (default when present, SDFC_LAVAPIPE)"), std::string::npos)
        << out;
    EXPECT_NE(out.find("Mesa 25."), std::string::npos) << out;
  }
}

// A machine without a GPU device node lists the bundled lavapipe alone: the
// loader would load (and the instance pay for) every GPU driver listed.
TEST(DriverSelect, NoGpuDriversListedWithoutAGpuNode) {
  const std::string dir = testing::TempDir() + "sdfc_dev_" + std::to_string(::getpid());
  ASSERT_EQ(std::system(("mkdir -p '" + dir + "/dri' && touch '" + dir + "/dri/card0'").c_str()), 0);
  EXPECT_FALSE(hasGpuDeviceNode(dir));  // a card node without a render node: display only
  ASSERT_EQ(std::system(("touch '" + dir + "/dri/renderD128'").c_str()), 0);
  EXPECT_TRUE(hasGpuDeviceNode(dir));
  ASSERT_EQ(std::system(("rm -r '" + dir + "/dri' && touch '" + dir + "/nvidiactl'").c_str()), 0);
  EXPECT_TRUE(hasGpuDeviceNode(dir));
  std::system(("rm -r '" + dir + "'").c_str());

  const DriverSelection& s = selectedDriver();
  const char* files = std::getenv("VK_DRIVER_FILES");
  if (!s.bundled || hasGpuDeviceNode()) GTEST_SKIP() << "not the bundled driver on a machine without a GPU";
  ASSERT_NE(files, nullptr);
  EXPECT_EQ(std::string(files), s.icd);
}

}  // namespace
}  // namespace sdfc
