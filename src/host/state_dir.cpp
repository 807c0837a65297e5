#include "host/state_dir.h"

#include <cstdlib>

#include <pwd.h>
#include <unistd.h>

namespace motwin::host {

std::optional<std::filesystem::path> default_state_dir() {
  if (const char* data_home = std::getenv("XDG_DATA_HOME"); data_home != nullptr && data_home[0] == '/') {
    return std::filesystem::path(data_home) / "motwin";
  }
  const char* home = std::getenv("HOME");
  if (home == nullptr || home[0] == '\0') {
    const passwd* entry = ::getpwuid(::getuid());
    home = entry != nullptr ? entry->pw_dir : nullptr;
  }
  if (home == nullptr || home[0] == '\0') return std::nullopt;
  return std::filesystem::path(home) / ".local" / "share" / "motwin";
}

}  // namespace motwin::host
