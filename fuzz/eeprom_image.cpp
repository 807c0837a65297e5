// The EEPROM image loader of `motwin serve` (src/host/eeprom_file.*): any bytes in
// <state-dir>/tmcm-1636.eeprom at start-up.
//
// Invariants:
// - bytes that validate are loaded as they are: the file is not rewritten, the module's image is
//   the payload, and encoding that payload again gives the same bytes;
// - anything else is reported by exactly one log line containing "damaged", the bytes are kept
//   unchanged as <image>.damaged, and the new file is a valid factory image;
// - never a crash, never an exception.
// Each input gets a fresh state directory under $TMPDIR (tmpfs in /dev/shm when present).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_support.h"
#include "host/eeprom_file.h"

namespace {

using namespace motwin;
namespace fs = std::filesystem;

std::vector<uint8_t> read_all(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

fs::path scratch_directory() {
  static const fs::path directory = [] {
    const fs::path base = fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    return base / ("motwin-fuzz-eeprom-" + std::to_string(::getpid()));
  }();
  return directory;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 64 * 1024) return 0;
  const host::EepromImageIdentity identity{std::string(fuzz::Tmcm1636::kName), fuzz::Tmcm1636::kNvmLayoutVersion,
                                           fuzz::Tmcm1636::kNvmLayout.total_size};
  const std::vector<uint8_t> bytes(data, data + size);
  const fs::path state_dir = scratch_directory();
  std::error_code ignored;
  fs::remove_all(state_dir, ignored);
  fs::create_directories(state_dir);
  const fs::path image = host::EepromFile::image_path(state_dir, identity.module_name);
  {
    std::ofstream file(image, std::ios::binary);
    file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }

  const std::string problem = host::EepromFile::validate(identity, bytes);
  std::vector<std::string> log;
  auto opened = host::EepromFile::open(state_dir, identity, &fuzz::Tmcm1636::format_factory_image,
                                       [&log](const std::string& line) { log.push_back(line); });
  FUZZ_CHECK(opened.file != nullptr, "open failed: %s", opened.error.c_str());
  const host::EepromFile& file = *opened.file;
  if (problem.empty()) {
    FUZZ_CHECK(file.load_outcome() == host::EepromLoadOutcome::kLoaded, "a valid image was not loaded");
    FUZZ_CHECK(log.empty(), "a valid image was reported: %s", log.front().c_str());
    FUZZ_CHECK(read_all(image) == bytes, "loading a valid image changed the file");
    FUZZ_CHECK(host::EepromFile::encode(identity, file.data()) == bytes, "the loaded payload encodes differently");
  } else {
    FUZZ_CHECK(file.load_outcome() == host::EepromLoadOutcome::kReplacedDamaged, "damaged (%s) but outcome %d",
               problem.c_str(), static_cast<int>(file.load_outcome()));
    FUZZ_CHECK(log.size() == 1 && log[0].find("damaged") != std::string::npos, "%zu log lines for a damaged image",
               log.size());
    FUZZ_CHECK(read_all(image.string() + ".damaged") == bytes, "the damaged bytes were not kept as they were");
    const std::vector<uint8_t> replaced = read_all(image);
    FUZZ_CHECK(host::EepromFile::validate(identity, replaced).empty(), "the replacement image is not valid");
    std::vector<uint8_t> factory(identity.payload_size);
    fuzz::Tmcm1636::format_factory_image(factory.data(), factory.size());
    FUZZ_CHECK(host::EepromFile::encode(identity, factory.data()) == replaced, "the replacement is not the factory image");
  }
  opened.file.reset();
  fs::remove_all(state_dir, ignored);
  return 0;
}
