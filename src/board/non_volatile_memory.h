// Board seam: the module's non-volatile memory (its "EEPROM image"). The core reads the image
// at power-up and writes small pieces (STAP, STGP, auto-stored SGP, program download).
// Implementations: RamNonVolatileMemory (tests, fuzzing) and host::EepromFile (a file
// written atomically in the state directory).
#pragma once

#include <cstddef>
#include <cstdint>

namespace motwin::board {

class NonVolatileMemory {
 public:
  virtual size_t size() const = 0;
  virtual const uint8_t* data() const = 0;
  // Replaces `length` bytes at `offset` and makes the whole image durable before returning
  // true. On false (out of bounds, medium full, I/O error) neither the image in memory nor
  // the stored one has changed.
  virtual bool write(size_t offset, const uint8_t* bytes, size_t length) = 0;

 protected:
  ~NonVolatileMemory() = default;
};

}  // namespace motwin::board
