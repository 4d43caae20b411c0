#include "window.h"

#include <cstdlib>
#include <stdexcept>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
// glfw3native.h's X11 part needs the Xlib and Xrandr headers (two more -dev
// packages) for this one function; GLFW 3.3 exports it with C linkage and
// Window = XID = unsigned long.
extern "C" unsigned long glfwGetX11Window(GLFWwindow* window);

#include "vk_check.h"

namespace sdfc::view {
namespace {

std::string g_last_glfw_error;

void onGlfwError(int, const char* description) { g_last_glfw_error = description ? description : ""; }

InputHandler* handlerOf(GLFWwindow* window) {
  return static_cast<InputHandler*>(glfwGetWindowUserPointer(window));
}

}  // namespace

Window::Window(int width, int height, const std::string& title, InputHandler* handler)
    : handler_(handler) {
  glfwSetErrorCallback(onGlfwError);
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland))
    throw NoDisplayError("no display (neither DISPLAY nor WAYLAND_DISPLAY is set)");
  if (!glfwInit()) throw NoDisplayError("cannot open the display: " + g_last_glfw_error);
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw NoDisplayError("the window system offers no Vulkan surface: " + g_last_glfw_error);
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  // Opens at the render size of the scene (or --size); the view follows a resize
  // (a new swapchain and accumulation, view_loop.cpp).
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    glfwTerminate();
    throw NoDisplayError("cannot create a window: " + g_last_glfw_error);
  }
  glfwSetWindowUserPointer(window_, handler_);
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int mods) {
    // Presses only: a held S must not write the image again and again.
    if (action == GLFW_PRESS) handlerOf(w)->onKey(key, mods);
  });
  glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int mods) {
    handlerOf(w)->onMouseButton(button, action == GLFW_PRESS, mods);
  });
  glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) {
    handlerOf(w)->onCursor(x, y);
  });
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) { handlerOf(w)->onScroll(dy); });
}

Window::~Window() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

std::vector<const char*> Window::requiredInstanceExtensions() {
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  if (!names) throw NoDisplayError("no Vulkan surface extensions: " + g_last_glfw_error);
  return std::vector<const char*>(names, names + count);
}

VkSurfaceKHR Window::createSurface(VkInstance instance) {
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  const VkResult result = glfwCreateWindowSurface(instance, window_, nullptr, &surface);
  if (result != VK_SUCCESS) throwVkError(result, "glfwCreateWindowSurface", __FILE__, __LINE__);
  return surface;
}

void Window::setTitle(const std::string& title) { glfwSetWindowTitle(window_, title.c_str()); }
bool Window::shouldClose() const { return glfwWindowShouldClose(window_); }
void Window::requestClose() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }
void Window::pollEvents() { glfwPollEvents(); }
void Window::waitEvents(double timeout_seconds) { glfwWaitEventsTimeout(timeout_seconds); }

void Window::framebufferSize(uint32_t& width, uint32_t& height) const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  width = uint32_t(w > 0 ? w : 0);
  height = uint32_t(h > 0 ? h : 0);
}

void Window::setSize(int width, int height) { glfwSetWindowSize(window_, width, height); }

unsigned long Window::nativeId() const {
  // GLFW 3.3 is X11-only on Debian 12 (glfw3-wayland is a separate library).
  return glfwGetX11Window(window_);
}

}  // namespace sdfc::view
