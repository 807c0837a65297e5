// A file replaced in one step: written to a temporary file next to it, synced, then renamed over
// it, so that a reader (a browser, a CI upload) never sees half a file and a failed run leaves
// the old one as it was (the way src/host/eeprom_file.h writes the EEPROM image).
#pragma once

#include <string>
#include <string_view>

#include "types/result.h"

namespace motwin::host {

class AtomicFile {
 public:
  // Makes the temporary file at once, so that a path that cannot be written fails before any
  // work is done: "cannot write /no/such/dir/page.html: No such file or directory".
  static Result<AtomicFile> create(const std::string& path);

  AtomicFile(AtomicFile&& other) noexcept;
  AtomicFile& operator=(AtomicFile&& other) = delete;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  // Without commit() the temporary file is removed and `path` is untouched.
  ~AtomicFile();

  // Writes `contents`, syncs and renames the temporary file to `path`.
  Result<void> commit(std::string_view contents);

  const std::string& path() const { return path_; }

 private:
  AtomicFile(std::string path, std::string temporary_path, int fd)
      : path_(std::move(path)), temporary_path_(std::move(temporary_path)), fd_(fd) {}

  std::string path_;
  std::string temporary_path_;
  int fd_ = -1;  // -1 once committed or moved from
};

}  // namespace motwin::host
