#include "cli/usage_hints.h"

#include <algorithm>
#include <regex>
#include <sstream>

namespace motwin::cli {
namespace {

// Edits (insert, delete, replace, swap two neighbours) from a to b: "sreve" is one from "serve".
size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

std::vector<std::string> command_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    names.push_back(command->get_name());
  }
  return names;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// The command the arguments selected (a parse error may come from inside it), or `app`.
const CLI::App& selected_command(const CLI::App& app) {
  const std::vector<CLI::App*> selected = app.get_subcommands();
  return selected.empty() ? app : *selected.front();
}

std::vector<std::string> option_names(const CLI::App& command) {
  std::vector<std::string> names;
  for (const CLI::Option* option : command.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  }
  return names;
}

}  // namespace

std::string closest_name(std::string_view typed, const std::vector<std::string>& candidates) {
  if (typed.empty()) return {};
  std::vector<std::string> extending;
  for (const std::string& candidate : candidates) {
    if (candidate.size() > typed.size() && candidate.compare(0, typed.size(), typed) == 0) extending.push_back(candidate);
  }
  if (extending.size() == 1) return extending.front();
  const size_t limit = std::max<size_t>(1, typed.size() / 3);
  std::string best;
  size_t best_distance = limit + 1;
  for (const std::string& candidate : candidates) {
    const size_t distance = edit_distance(typed, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  return best;
}

std::string unknown_command_message(const CLI::App& app, int argc, const char* const* argv) {
  if (argc < 2 || argv[1][0] == '-' || argv[1][0] == '\0') return {};
  const std::string typed = argv[1];
  const std::vector<std::string> names = command_names(app);
  if (std::find(names.begin(), names.end(), typed) != names.end()) return {};
  const std::string closest = closest_name(typed, names);
  if (!closest.empty()) return "unknown command \"" + typed + "\"; did you mean \"" + closest + "\"?";
  return "unknown command \"" + typed + "\" (commands: " + joined(names) + ")";
}

std::string explain_parse_error(const CLI::App& app, const CLI::Error& error) {
  const std::string message = error.what();
  std::smatch match;
  static const std::regex kRepeated("(.+): At Most 1 required but received ([0-9]+)");
  if (std::regex_match(message, match, kRepeated)) {
    return match[1].str() + " is given " + match[2].str() + " times; it takes one value";
  }
  if (message == "A subcommand is required") return "a command is required: " + joined(command_names(app));
  static const std::regex kUnexpected("The following arguments? (was|were) not expected: (.+)");
  if (std::regex_match(message, match, kUnexpected)) {
    const CLI::App& command = selected_command(app);
    std::istringstream arguments(match[2].str());
    for (std::string argument; arguments >> argument;) {
      if (argument.rfind("--", 0) != 0) continue;
      const std::string option = argument.substr(0, argument.find('='));
      const std::string closest = closest_name(option, option_names(command));
      const std::string of_command = command.get_name().empty() ? "" : " of " + command.get_name();
      if (!closest.empty()) return "unknown option " + option + of_command + "; did you mean " + closest + "?";
    }
  }
  return message;
}

}  // namespace motwin::cli
