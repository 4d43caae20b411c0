#include "driver_select.h"

#include <dirent.h>
#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

#include "vk_check.h"

namespace sdfc {
namespace {

constexpr const char* kManifestName = "lvp_icd.x86_64.json";

bool fileExists(const std::string& path) { return !path.empty() && access(path.c_str(), R_OK) == 0; }

std::string parentDir(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

std::string executableDir() {
  char buffer[4096];
  const ssize_t n = readlink("/proc/self/exe", buffer, sizeof(buffer) - 1);
  if (n <= 0) return "";
  return parentDir(std::string(buffer, static_cast<size_t>(n)));
}

// The folder of the file this code was loaded from when it is not the
// executable: the Python module (site-packages/sdfc/_sdfc*.so), beside which
// a wheel carries its lavapipe-25/ ("" for the executable itself).
std::string sharedObjectDir() {
  Dl_info info{};
  if (!dladdr(reinterpret_cast<void*>(&sharedObjectDir), &info) || !info.dli_fname) return "";
  char resolved[PATH_MAX];
  if (!realpath(info.dli_fname, resolved)) return "";
  char exe[PATH_MAX];
  if (realpath("/proc/self/exe", exe) && std::string(exe) == resolved) return "";
  return parentDir(resolved);
}

// The manifest's "library_path", resolved against the manifest's folder the way
// the loader does for a relative path ("" when unreadable).
std::string manifestLibrary(const std::string& manifest) {
  std::ifstream in(manifest);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  size_t at = s.find("\"library_path\"");
  if (at == std::string::npos) return "";
  at = s.find('"', s.find(':', at));
  const size_t end = at == std::string::npos ? at : s.find('"', at + 1);
  if (end == std::string::npos) return "";
  const std::string path = s.substr(at + 1, end - at - 1);
  return path.empty() || path[0] == '/' ? path : parentDir(manifest) + "/" + path;
}

// The system's driver manifests except its own lavapipe, so a GPU stays
// visible next to the bundled CPU driver (the loader's default folders); none
// on a machine without a GPU device node: the loader loads every listed driver
// at instance creation (radeon, intel, hasvk: 10 ms of CPU, each finding no
// device; bench/results/fixed_costs.md).
std::vector<std::string> systemManifestsExceptLavapipe() {
  std::vector<std::string> result;
  if (!hasGpuDeviceNode()) return result;
  for (const char* dir : {"/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d",
                          "/usr/share/vulkan/icd.d"}) {
    DIR* d = opendir(dir);
    if (!d) continue;
    while (const dirent* entry = readdir(d)) {
      const std::string name = entry->d_name;
      if (name.size() < 5 || name.compare(name.size() - 5, 5, ".json") != 0) continue;
      if (name.rfind("lvp_icd", 0) == 0) continue;
      result.push_back(std::string(dir) + "/" + name);
    }
    closedir(d);
  }
  return result;
}

}  // namespace

bool hasGpuDeviceNode(const std::string& dev) {
  // DRM render nodes (Mesa's GPU drivers, virtio), NVIDIA's own driver, WSL's dxg.
  if (DIR* d = opendir((dev + "/dri").c_str())) {
    bool found = false;
    while (const dirent* entry = readdir(d))
      if (std::string(entry->d_name).rfind("renderD", 0) == 0) found = true;
    closedir(d);
    if (found) return true;
  }
  return access((dev + "/nvidiactl").c_str(), F_OK) == 0 ||
         access((dev + "/dxg").c_str(), F_OK) == 0;
}

namespace {

std::mutex g_mutex;
bool g_selected = false;
DriverSelection g_selection;

DriverSelection apply(DriverChoice choice) {
  DriverSelection s;
  s.requested = choice;
  const bool user_set = std::getenv("VK_DRIVER_FILES") || std::getenv("VK_ICD_FILENAMES");
  if (choice == DriverChoice::System) {
    // The loader's own search: drop variables a wrapper may have exported.
    unsetenv("VK_DRIVER_FILES");
    unsetenv("VK_ICD_FILENAMES");
    s.reason = "system drivers (--driver system)";
    return s;
  }
  // SDFC_LAVAPIPE names the driver to use: its absence is an error, not a
  // silent fall back to the system's (whose images may differ).
  const char* user_env = std::getenv("SDFC_LAVAPIPE");
  const std::string user_dir = user_env ? user_env : "";
  if (choice == DriverChoice::Auto && user_set && user_dir.empty()) {
    s.reason = "VK_DRIVER_FILES / VK_ICD_FILENAMES set by the user";
    return s;
  }
  const bool must = choice == DriverChoice::Bundled || !user_dir.empty();
  const std::string who = user_dir.empty() ? "--driver bundled" : "SDFC_LAVAPIPE=" + user_dir;
  const std::string manifest = bundledDriverManifest();
  const std::string library = manifest.empty() ? "" : manifestLibrary(manifest);
  if (!fileExists(library)) {
    if (!user_dir.empty())
      throw RuntimeError(who + ": no lavapipe there (a folder holding " + kManifestName +
                         " and the library it names, such as a checkout's build/lavapipe-25, or that file)");
    if (must) throw RuntimeError(who + ": no bundled lavapipe (run tools/lavapipe25.sh fetch)");
    s.reason = "system drivers (no bundled lavapipe; tools/lavapipe25.sh fetch adds it, SDFC_LAVAPIPE names one)";
    return s;
  }
  // The bundled driver links libdrm >= 2.4.121 (the system has 2.4.114): loaded
  // first by path, its soname satisfies the driver's dependency (LD_LIBRARY_PATH
  // is read only at process start, so setting it here would be too late).
  const std::string libdrm = parentDir(library) + "/libdrm.so.2";
  if (!dlopen(libdrm.c_str(), RTLD_NOW | RTLD_GLOBAL)) {
    if (must) throw RuntimeError(who + ": cannot load " + libdrm);
    s.reason = "system drivers (bundled lavapipe's libdrm failed to load)";
    return s;
  }
  std::string files = manifest;
  for (const std::string& other : systemManifestsExceptLavapipe()) files += ":" + other;
  setenv("VK_DRIVER_FILES", files.c_str(), 1);
  setenv("VK_ICD_FILENAMES", files.c_str(), 1);  // loaders before 1.3.207
  s.bundled = true;
  s.icd = manifest;
  s.reason = choice == DriverChoice::Bundled ? "bundled lavapipe (--driver bundled)"
                                             : "bundled lavapipe (default when present)";
  if (!user_dir.empty()) s.reason.insert(s.reason.size() - 1, ", SDFC_LAVAPIPE");
  return s;
}

}  // namespace

bool parseDriverChoice(const std::string& text, DriverChoice& choice) {
  if (text == "auto") choice = DriverChoice::Auto;
  else if (text == "system") choice = DriverChoice::System;
  else if (text == "bundled") choice = DriverChoice::Bundled;
  else return false;
  return true;
}

const char* driverChoiceName(DriverChoice choice) {
  switch (choice) {
    case DriverChoice::System: return "system";
    case DriverChoice::Bundled: return "bundled";
    default: return "auto";
  }
}

DriverChoice driverChoiceFromEnv() {
  DriverChoice choice = DriverChoice::Auto;
  const char* value = std::getenv("SDFC_DRIVER");
  if (value) parseDriverChoice(value, choice);
  return choice;
}

std::string bundledDriverManifest() {
  std::vector<std::string> candidates;
  const char* user = std::getenv("SDFC_LAVAPIPE");
  if (user && *user) {
    // The user's folder (or manifest) and nothing else.
    const std::string u = user;
    const bool is_manifest = u.size() > 5 && u.compare(u.size() - 5, 5, ".json") == 0;
    candidates.push_back(is_manifest ? u : u + "/" + kManifestName);
  } else {
    const std::string module_dir = sharedObjectDir();
    if (!module_dir.empty()) candidates.push_back(module_dir + "/lavapipe-25/" + kManifestName);
    const std::string exe_dir = executableDir();
    if (!exe_dir.empty()) candidates.push_back(exe_dir + "/../lavapipe-25/" + kManifestName);
#ifdef SDFC_BUNDLED_DRIVER_DIR
    candidates.push_back(std::string(SDFC_BUNDLED_DRIVER_DIR) + "/" + kManifestName);
#endif
  }
  for (const std::string& c : candidates) {
    if (!fileExists(c)) continue;
    char resolved[PATH_MAX];
    return realpath(c.c_str(), resolved) ? std::string(resolved) : c;
  }
  return "";
}

const DriverSelection& selectDriver(DriverChoice choice) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_selected) {
    g_selection = apply(choice);
    g_selected = true;
  }
  return g_selection;
}

const DriverSelection& selectedDriver() {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (g_selected) return g_selection;
  }
  return selectDriver(driverChoiceFromEnv());
}

}  // namespace sdfc
