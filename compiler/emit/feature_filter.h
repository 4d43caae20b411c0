// Resolves the kernel's SDFC_* feature conditionals at emission time, so the
// emitted GLSL holds only the code the scene uses. Handles `#ifdef X`,
// `#ifndef X`, `#if defined(A) || defined(B) ...`, `#else`, `#endif`, nested;
// every other preprocessor line passes through to glslang untouched.
#pragma once
#include <set>
#include <string>
#include <string_view>

namespace sdfc {

// Returns the text with SDFC_ conditionals resolved against `defined`, or
// throws std::runtime_error for an unbalanced or unsupported conditional.
std::string filterFeatures(std::string_view text, const std::set<std::string>& defined);

}  // namespace sdfc
