// Usage errors that point at the fix: a mistyped command or option names the closest real one,
// a repeated single-use option says which and how often (CLI11's own messages say neither).
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace motwin::cli {

// The candidate `typed` most likely meant: a unique one it is a prefix of, else the nearest by
// edit distance if that is at most a third of its length (at least 1). Empty when none is close.
std::string closest_name(std::string_view typed, const std::vector<std::string>& candidates);

// When argv's first argument is no option and names no command: the error line (without the
// "motwin: error: " prefix), naming the closest command or listing them. Otherwise empty.
std::string unknown_command_message(const CLI::App& app, int argc, const char* const* argv);

// CLI11's message for a parse error of `app` (or of the command it selected), made plain.
std::string explain_parse_error(const CLI::App& app, const CLI::Error& error);

}  // namespace motwin::cli
