#include "script.h"

#include <GLFW/glfw3.h>

#include "api/option_limits.h"

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace sdfc::view {
namespace {

struct Arity {
  size_t min, max;
};

// verb -> number of arguments (run takes the rest of the line).
const std::map<std::string, Arity>& verbs() {
  static const std::map<std::string, Arity> table = {
      {"wait", {1, 1}},       {"wait-spp", {1, 1}}, {"wait-reload", {0, 0}}, {"wait-idle", {0, 0}},
      {"key", {1, 1}},        {"drag", {3, 4}},     {"scroll", {1, 1}},      {"spp", {1, 1}},
      {"save", {1, 1}},       {"write-file", {1, 1}}, {"run", {1, 1000}},    {"quit", {0, 0}},
      {"log", {1, 1000}},     {"resize", {2, 2}},
  };
  return table;
}

bool isNumber(const std::string& s) {
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size();
}

}  // namespace

int keyCodeForName(const std::string& name) {
  static const std::map<std::string, int> named = {
      {"space", GLFW_KEY_SPACE},   {"escape", GLFW_KEY_ESCAPE}, {"period", GLFW_KEY_PERIOD},
      {"home", GLFW_KEY_HOME},     {"enter", GLFW_KEY_ENTER},
  };
  if (auto it = named.find(name); it != named.end()) return it->second;
  if (name.size() == 1) {
    const char c = name[0];
    if (c >= '0' && c <= '9') return GLFW_KEY_0 + (c - '0');
    if (c >= 'a' && c <= 'z') return GLFW_KEY_A + (c - 'a');
  }
  return -1;
}

std::vector<ScriptCommand> loadScript(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read script '" + path + "'");
  std::vector<ScriptCommand> commands;
  std::string line;
  int number = 0;
  auto fail = [&](const std::string& message) {
    throw std::runtime_error(path + ":" + std::to_string(number) + ": error: " + message);
  };
  while (std::getline(in, line)) {
    ++number;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream words(line);
    ScriptCommand c;
    c.line = number;
    words >> c.verb;
    const size_t after = line.find(c.verb) + c.verb.size();
    c.rest = line.substr(std::min(line.size(), line.find_first_not_of(" \t", after)));
    while (!c.rest.empty() && (c.rest.back() == '\r' || c.rest.back() == ' ')) c.rest.pop_back();
    for (std::string w; words >> w;) c.args.push_back(w);
    // A path is the rest of the line, spaces and all; quotes around it are dropped.
    if ((c.verb == "save" || c.verb == "write-file") && !c.rest.empty()) {
      std::string path = c.rest;
      if (path.size() >= 2 && (path[0] == '"' || path[0] == '\'') && path.back() == path[0])
        path = path.substr(1, path.size() - 2);
      c.args = {path};
    }
    const auto it = verbs().find(c.verb);
    if (it == verbs().end()) fail("unknown command '" + c.verb + "'");
    if (c.args.size() < it->second.min || c.args.size() > it->second.max)
      fail("'" + c.verb + "' takes " + std::to_string(it->second.min) +
           (it->second.max != it->second.min ? " or more" : "") + " arguments");
    if (c.verb == "key" && keyCodeForName(c.args[0]) < 0) fail("unknown key '" + c.args[0] + "'");
    if (c.verb == "drag") {
      if (c.args[0] != "left" && c.args[0] != "middle" && c.args[0] != "right")
        fail("drag expects left, middle or right");
      for (size_t i = 1; i < c.args.size(); ++i)
        if (!isNumber(c.args[i])) fail("drag expects numbers after the button");
    }
    if (c.verb == "resize" && !(isNumber(c.args[0]) && isNumber(c.args[1])))
      fail("resize expects a width and a height in pixels");
    if ((c.verb == "wait" || c.verb == "wait-spp" || c.verb == "scroll" || c.verb == "spp") &&
        !isNumber(c.args[0]))
      fail("'" + c.verb + "' expects a number");
    // The same range as --spp and Python's spp (api/option_limits.h).
    if (c.verb == "spp")
      if (const std::string problem = api::optionProblem(api::Option::Spp, std::atof(c.args[0].c_str()), "'spp'");
          !problem.empty())
        fail(problem);
    commands.push_back(std::move(c));
  }
  return commands;
}

}  // namespace sdfc::view
