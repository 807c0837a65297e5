// The EEPROM image loader of `motwin serve` (src/host/eeprom_file.*): any bytes in
// <state-dir>/<module>.eeprom at start-up.
//
// Input: byte 0 picks the module (mod 3: TMCM-1636, TMCM-142, TMCM-3216: each with its name,
// layout version, image size and factory image, host::eeprom_identity_of as `motwin serve` uses
// it); the rest is the file. Invariants:
// - bytes that validate are loaded as they are: the file is not rewritten, the module's image is
//   the payload, and encoding that payload again gives the same bytes;
// - a valid image of an older layout the module migrates (TMCM-142 layout 1) is migrated: one log
//   line, the module's image is what its migrate_image() makes of the payload, the file valid;
// - anything else is reported by exactly one log line containing "damaged", the bytes are kept
//   unchanged as <image>.damaged, and the new file is a valid factory image;
// - never a crash, never an exception.
// Each input gets a fresh state directory under $TMPDIR (tmpfs in /dev/shm when present).
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/modules/tmcm142/tmcm142.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "fuzz_support.h"
#include "host/eeprom_file.h"
#include "host/module_eeprom.h"

namespace {

using namespace motwin;
namespace fs = std::filesystem;

// One read of the whole file (an istreambuf_iterator per byte cost almost half of each input's time).
std::vector<uint8_t> read_all(const fs::path& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) return {};
  std::vector<uint8_t> bytes(static_cast<size_t>(file.tellg()));
  file.seekg(0);
  file.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<size_t>(file.gcount()) != bytes.size()) bytes.resize(static_cast<size_t>(file.gcount()));
  return bytes;
}

// The module's factory image as a file holds it, encoded once per process, and valid: a file
// equal to it is valid too (validate() reads nothing but the bytes), which spares the check of
// each replacement two CRCs over the image.
template <typename Device>
const std::vector<uint8_t>& factory_file(const host::EepromImageIdentity& identity) {
  static const std::vector<uint8_t> encoded = [&identity] {
    std::vector<uint8_t> factory(identity.payload_size);
    Device::format_factory_image(factory.data(), factory.size());
    std::vector<uint8_t> file = host::EepromFile::encode(identity, factory.data());
    FUZZ_CHECK(host::EepromFile::validate(identity, file).ok(), "%s: the factory image file is not valid",
               identity.module_name.c_str());
    return file;
  }();
  return encoded;
}

// The state directory, one per process, created (empty) before the first input and removed at
// exit; each input removes the files it made (the image, its .damaged copy), so the next one
// starts on an empty directory but for the lock file, which `EepromFile::open` creates or
// reuses alike. (Creating and removing the directory for every input cost a tenth of its time.)
struct ScratchDirectory {
  fs::path path;
  ScratchDirectory() {
    const fs::path base = fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    path = base / ("motwin-fuzz-eeprom-" + std::to_string(::getpid()));
    std::error_code ignored;
    fs::remove_all(path, ignored);
    fs::create_directories(path);
  }
  ~ScratchDirectory() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

const fs::path& scratch_directory() {
  static const ScratchDirectory directory;
  return directory.path;
}

// One input against one module's image file.
template <typename Device>
void load(const std::vector<uint8_t>& bytes) {
  const host::EepromImageIdentity identity = host::eeprom_identity_of<Device>();
  const fs::path& state_dir = scratch_directory();
  const fs::path image = host::EepromFile::image_path(state_dir, identity.module_name);
  {
    std::ofstream file(image, std::ios::binary);
    file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }

  const std::string problem = host::EepromFile::validate(identity, bytes).error();
  // A valid image of an older layout the module migrates (the TMCM-142's layout 1): what it must
  // become, or empty.
  std::vector<uint8_t> migrated_payload;
  if (!problem.empty() && identity.migrate_layout && bytes.size() >= host::EepromFile::kHeaderSize) {
    host::EepromImageIdentity stored = identity;
    stored.layout_version = static_cast<uint32_t>(bytes[48]) | (static_cast<uint32_t>(bytes[49]) << 8) |
                            (static_cast<uint32_t>(bytes[50]) << 16) | (static_cast<uint32_t>(bytes[51]) << 24);
    if (stored.layout_version != identity.layout_version && host::EepromFile::validate(stored, bytes).ok()) {
      std::vector<uint8_t> payload(bytes.begin() + host::EepromFile::kHeaderSize, bytes.end());
      if (identity.migrate_layout(stored.layout_version, payload.data(), payload.size())) migrated_payload = payload;
    }
  }
  std::vector<std::string> log;
  auto opened = host::EepromFile::open(
      state_dir, identity, [](uint8_t* image, size_t size) { Device::format_factory_image(image, size); },
      [&log](const std::string& line) { log.push_back(line); });
  FUZZ_CHECK(opened.ok(), "%s: open failed: %s", identity.module_name.c_str(), opened.error().c_str());
  const host::EepromFile& file = **opened;
  if (problem.empty()) {
    FUZZ_CHECK(file.load_outcome() == host::EepromLoadOutcome::kLoaded, "a valid image was not loaded");
    FUZZ_CHECK(log.empty(), "a valid image was reported: %s", log.front().c_str());
    FUZZ_CHECK(read_all(image) == bytes, "loading a valid image changed the file");
    // The payload as it was; the header may name another firmware (a firmware change is no
    // damage) and hold bytes after the NULs of its text fields.
    FUZZ_CHECK(std::equal(file.data(), file.data() + file.size(), bytes.begin() + host::EepromFile::kHeaderSize,
                          bytes.end()),
               "the loaded payload differs from the file's");
  } else if (!migrated_payload.empty()) {
    FUZZ_CHECK(file.load_outcome() == host::EepromLoadOutcome::kMigrated, "an older layout was not migrated");
    FUZZ_CHECK(log.size() == 1 && log[0].find("migrated") != std::string::npos, "%zu log lines for a migration",
               log.size());
    FUZZ_CHECK(std::equal(file.data(), file.data() + file.size(), migrated_payload.begin(), migrated_payload.end()),
               "the migrated payload differs from the module's migration");
    const std::vector<uint8_t> written = read_all(image);
    FUZZ_CHECK(host::EepromFile::validate(identity, written).ok(), "the migrated image file is not valid");
  } else {
    FUZZ_CHECK(file.load_outcome() == host::EepromLoadOutcome::kReplacedDamaged, "damaged (%s) but outcome %d",
               problem.c_str(), static_cast<int>(file.load_outcome()));
    FUZZ_CHECK(log.size() == 1 && log[0].find("damaged") != std::string::npos, "%zu log lines for a damaged image",
               log.size());
    FUZZ_CHECK(read_all(image.string() + ".damaged") == bytes, "the damaged bytes were not kept as they were");
    // The factory image file, which is valid (factory_file()): the replacement is valid too.
    const std::vector<uint8_t> replaced = read_all(image);
    FUZZ_CHECK(factory_file<Device>(identity) == replaced, "the replacement is not the factory image");
  }
  opened->reset();
  std::error_code ignored;
  fs::remove(image, ignored);
  fs::remove(image.string() + ".damaged", ignored);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 64 * 1024) return 0;
  const std::vector<uint8_t> bytes(data + 1, data + size);
  switch (data[0] % 3) {
    case 0: load<modules::tmcm1636::Tmcm1636>(bytes); break;
    case 1: load<modules::tmcm142::Tmcm142>(bytes); break;
    default: load<modules::tmcm3216::Tmcm3216>(bytes); break;
  }
  return 0;
}
