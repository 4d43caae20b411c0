// CLI11's parse errors in sdfc's words: "sdfc: error: " (added by main),
// a suggestion for a mistyped subcommand or option, a pointer to --help.
#include "usage_errors.h"

#include <algorithm>
#include <cctype>

#include "diag/diagnostics.h"

namespace sdfc {
namespace {

// The subcommand the arguments chose (the deepest one parsed), or the app.
const CLI::App* chosenCommand(const CLI::App& app) {
  const CLI::App* at = &app;
  for (bool deeper = true; deeper;) {
    deeper = false;
    for (const CLI::App* sub : at->get_subcommands()) {
      at = sub;
      deeper = true;
      break;
    }
  }
  return at;
}

std::string commandPath(const CLI::App* command) {
  std::string path;
  for (const CLI::App* c = command; c && c->get_parent(); c = c->get_parent())
    path = c->get_name() + (path.empty() ? "" : " " + path);
  return path;
}

std::string helpHint(const CLI::App* command) {
  const std::string path = commandPath(command);
  return "; see 'sdfc " + (path.empty() ? "" : path + " ") + "--help'";
}

// Every option spelling a command accepts, with its dashes; options of the
// app itself (--driver) are accepted after a subcommand too.
std::vector<std::string> optionNames(const CLI::App* command) {
  std::vector<std::string> names;
  for (const CLI::App* c = command; c; c = c->get_parent())
    for (const CLI::Option* o : c->get_options()) {
      for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
      for (const std::string& s : o->get_snames()) names.push_back("-" + s);
    }
  return names;
}

std::vector<std::string> subcommandNames(const CLI::App* command) {
  std::vector<std::string> names;
  for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(sub->get_name());
  return names;
}

}  // namespace

std::string usageErrorText(const CLI::App& app, const CLI::ParseError& error, int argc, char** argv) {
  const CLI::App* command = chosenCommand(app);
  // No subcommand chosen: the first word that is not an option was meant as one.
  if (command->get_require_subcommand_min() > 0 && command->get_subcommands().empty()) {
    const std::vector<std::string> names = subcommandNames(command);
    for (int i = 1; i < argc; ++i) {
      const std::string word = argv[i];
      if (word.empty() || word[0] == '-' || word == commandPath(command)) continue;
      if (std::find(names.begin(), names.end(), word) != names.end()) break;
      std::string text = "unknown command '" + word + "'";
      const std::string near = nearestName(word, names);
      if (!near.empty()) text += "; did you mean '" + near + "'?";
      return text + helpHint(command);
    }
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    const std::string path = commandPath(command);
    return "'sdfc" + (path.empty() ? "" : " " + path) + "' needs a command: " + list + helpHint(command);
  }
  // Options the command does not have: the closest one it does.
  if (dynamic_cast<const CLI::ExtrasError*>(&error)) {
    const std::vector<std::string> names = optionNames(command);
    for (int i = 1; i < argc; ++i) {
      const std::string word = argv[i];
      if (word.size() < 2 || word[0] != '-' || std::isdigit(static_cast<unsigned char>(word[1])) ||
          word[1] == '.')
        continue;  // not an option (a negative number is a value)
      const std::string flag = word.substr(0, word.find('='));
      if (std::find(names.begin(), names.end(), flag) != names.end() ||
          (flag.size() > 2 && flag[1] != '-' &&
           std::find(names.begin(), names.end(), flag.substr(0, 2)) != names.end()))
        continue;  // known, or a short option with its value attached (-Wno-bound)
      std::string text = "unknown option '" + flag + "'";
      const std::string path = commandPath(command);
      if (!path.empty()) text += " for 'sdfc " + path + "'";
      const std::string near = nearestName(flag, names);
      if (!near.empty()) text += "; did you mean '" + near + "'?";
      return text + helpHint(command);
    }
  }
  return error.what() + helpHint(command);
}

}  // namespace sdfc
