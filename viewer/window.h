// The window: GLFW for the native window, its Vulkan surface and input events.
// Input is forwarded to an InputHandler so a script can drive the same handlers.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

struct GLFWwindow;

namespace sdfc::view {

class InputHandler {
 public:
  virtual ~InputHandler() = default;
  virtual void onKey(int key, int mods) = 0;                     // GLFW_KEY_*, on press
  virtual void onMouseButton(int button, bool down, int mods) = 0;
  virtual void onCursor(double x, double y) = 0;                  // window pixels
  virtual void onScroll(double dy) = 0;
};

// Thrown when no display can be opened (the caller points to `sdfc render`).
class NoDisplayError : public std::runtime_error {
 public:
  explicit NoDisplayError(const std::string& message) : std::runtime_error(message) {}
};

class Window {
 public:
  // Initialises GLFW and opens a resizable window without a client API.
  // Throws NoDisplayError when there is no display or no Vulkan support.
  Window(int width, int height, const std::string& title, InputHandler* handler);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  // Instance extensions the surface needs (VK_KHR_surface + the platform's).
  static std::vector<const char*> requiredInstanceExtensions();
  VkSurfaceKHR createSurface(VkInstance instance);

  void setTitle(const std::string& title);
  bool shouldClose() const;
  void requestClose();
  void pollEvents();
  void waitEvents(double timeout_seconds);
  // The drawable size in pixels (0 x 0 while minimised), and a request to change
  // it (the script's `resize`; a person drags the window's border).
  void framebufferSize(uint32_t& width, uint32_t& height) const;
  void setSize(int width, int height);
  // The X11 window id (for screenshots), 0 on other platforms.
  unsigned long nativeId() const;

 private:
  GLFWwindow* window_ = nullptr;
  InputHandler* handler_ = nullptr;
};

}  // namespace sdfc::view
