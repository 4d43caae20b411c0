// Text files compiled into the binary (the GLSL kernel and the shared
// interface header), looked up by their path relative to compiler/emit or
// runtime: "kernel/prelude.glsl", "kernel/pathtrace.glsl", "shader_interface.h".
#pragma once
#include <string_view>

namespace sdfc {
// Empty view when no such file was embedded.
std::string_view embeddedSource(std::string_view name);
}
