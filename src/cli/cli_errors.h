// Exit statuses and error lines shared by the `motwin` subcommands. A step of a command that can
// fail returns Result (docs/architecture.md, "Errors outside the core"); the command turns the
// failure into its `motwin: error:` line and its exit status.
#pragma once

#include <iostream>
#include <string_view>

namespace motwin::cli {

inline constexpr int kExitSuccess = 0;
inline constexpr int kExitModuleError = 1;  // the module answered with an error status
inline constexpr int kExitUsageError = 2;   // bad arguments, no connection, no or bad reply

// "motwin: error: MESSAGE" on stderr.
inline void print_error(std::string_view message) { std::cerr << "motwin: error: " << message << '\n'; }

// Ends a command on a usage error: prints its error line and gives kExitUsageError.
inline int usage_error(std::string_view message) {
  print_error(message);
  return kExitUsageError;
}

}  // namespace motwin::cli
