// The files of the web console and of trace pages, built into the binary (cmake/embed_files.cmake):
// the pages under web/site/ and web/trace/ of the source tree and the plotting library from
// web/node_modules/ (npm, pinned in web/package-lock.json), so that `motwin` needs nothing from
// disk or the network to serve a page or write one. docs/web-console.md says what is where.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

namespace motwin::host::web {

// One embedded file as the generator writes it; `bytes` is followed by a NUL.
struct EmbeddedFile {
  const char* key;  // path below web/ in the source tree, e.g. "site/index.html", "vendor/uPlot.iife.min.js"
  const unsigned char* bytes;
  size_t size;
};

extern const EmbeddedFile kEmbeddedFiles[];
extern const size_t kEmbeddedFileCount;

struct WebAsset {
  std::string_view key;
  std::string_view content_type;  // with charset for text, as sent in Content-Type
  std::string_view bytes;
};

// Every embedded file, in the generator's order.
std::span<const EmbeddedFile> embedded_files();

// The file stored under `key` ("site/index.html"), or nothing.
std::optional<WebAsset> find_web_asset(std::string_view key);

// Content-Type by file name extension; application/octet-stream for unknown ones.
std::string_view content_type_for(std::string_view key);

}  // namespace motwin::host::web
