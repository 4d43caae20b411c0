// Which Vulkan driver the process uses: the system's, or Mesa 25's lavapipe that
// tools/setup.sh unpacks into build/lavapipe-25 (tools/lavapipe25.sh). The
// choice is made once, before the first Vulkan call, by pointing the Vulkan
// loader's VK_DRIVER_FILES at the bundled manifest (docs/lavapipe.md).
#pragma once
#include <string>

namespace sdfc {

enum class DriverChoice {
  Auto,     // bundled lavapipe when present and the user set no loader variables
  System,   // the loader's own search (the system's drivers)
  Bundled,  // the bundled lavapipe, or an error when it is missing
};

struct DriverSelection {
  DriverChoice requested = DriverChoice::Auto;
  bool bundled = false;     // the bundled lavapipe is the process's CPU driver
  std::string icd;          // its manifest, when bundled
  std::string reason;       // one line for `sdfc devices` / --version
};

// "auto" | "system" | "bundled"; false for anything else.
bool parseDriverChoice(const std::string& text, DriverChoice& choice);
const char* driverChoiceName(DriverChoice choice);

// The choice from env SDFC_DRIVER (auto when unset or unknown).
DriverChoice driverChoiceFromEnv();

// The bundled manifest ("" when absent): env SDFC_LAVAPIPE's folder (or the
// manifest it names) alone when set; otherwise, in order, lavapipe-25/ beside
// the Python module (an installed wheel carries one there), <exe
// dir>/../lavapipe-25/, then the configured build tree's (not in a wheel).
// Each is a folder holding lvp_icd.x86_64.json.
std::string bundledDriverManifest();

// Whether `dev` (normally /dev) has a node a GPU driver opens: a DRM render
// node, NVIDIA's nvidiactl or WSL's dxg. Without one the bundled lavapipe is
// the only driver listed for the loader (GPU drivers would find nothing).
bool hasGpuDeviceNode(const std::string& dev = "/dev");

// Applies `choice` once per process (later calls return the first result):
// sets or clears VK_DRIVER_FILES / VK_ICD_FILENAMES and preloads the bundled
// libdrm. Throws RuntimeError when Bundled is asked for and absent, or when
// SDFC_LAVAPIPE is set and names no manifest (System excepted). Must run
// before the first Vulkan call; createContext() and listDevices() call
// selectedDriver() themselves.
const DriverSelection& selectDriver(DriverChoice choice);
// selectDriver(driverChoiceFromEnv()) unless a choice was already made.
const DriverSelection& selectedDriver();

}  // namespace sdfc
