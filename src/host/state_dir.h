// Where virtual modules keep their EEPROM images between runs.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace motwin::host {

// `--state-dir none`: the EEPROM image lives in memory only and starts from factory defaults.
inline constexpr std::string_view kNoStateDir = "none";

// $XDG_DATA_HOME/motwin, or $HOME/.local/share/motwin (XDG base directory specification: a
// relative XDG_DATA_HOME is ignored). nullopt when neither variable nor the password database
// gives a home directory.
std::optional<std::filesystem::path> default_state_dir();

}  // namespace motwin::host
