#include "host/web/web_assets.h"

#include <array>
#include <utility>

namespace motwin::host::web {

std::span<const EmbeddedFile> embedded_files() { return {kEmbeddedFiles, kEmbeddedFileCount}; }

std::string_view content_type_for(std::string_view key) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 9> kTypes{{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".ico", "image/x-icon"},
      {".txt", "text/plain; charset=utf-8"},
      {".md", "text/plain; charset=utf-8"},
  }};
  for (const auto& [extension, type] : kTypes) {
    if (key.ends_with(extension)) return type;
  }
  return "application/octet-stream";
}

std::optional<WebAsset> find_web_asset(std::string_view key) {
  for (const EmbeddedFile& file : embedded_files()) {
    if (key == file.key) {
      return WebAsset{file.key, content_type_for(file.key),
                      std::string_view(reinterpret_cast<const char*>(file.bytes), file.size)};
    }
  }
  return std::nullopt;
}

}  // namespace motwin::host::web
