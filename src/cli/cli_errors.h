// Exit statuses and error lines shared by the `motwin` subcommands.
#pragma once

#include <iostream>
#include <string_view>

namespace motwin::cli {

inline constexpr int kExitSuccess = 0;
inline constexpr int kExitModuleError = 1;  // the module answered with an error status
inline constexpr int kExitUsageError = 2;   // bad arguments, no connection, no or bad reply

// "motwin: error: MESSAGE" on stderr.
inline void print_error(std::string_view message) { std::cerr << "motwin: error: " << message << '\n'; }

}  // namespace motwin::cli
