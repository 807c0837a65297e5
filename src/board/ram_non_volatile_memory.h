// A NonVolatileMemory held in RAM: for tests, fuzzing and `--state-dir none`.
#pragma once

#include <array>
#include <cstring>

#include "board/non_volatile_memory.h"

namespace motwin::board {

template <size_t kSize>
class RamNonVolatileMemory final : public NonVolatileMemory {
 public:
  size_t size() const override { return kSize; }
  const uint8_t* data() const override { return bytes_.data(); }
  bool write(size_t offset, const uint8_t* bytes, size_t length) override {
    if (offset > kSize || length > kSize - offset || fail_writes_) return false;
    std::memcpy(bytes_.data() + offset, bytes, length);
    ++write_count_;
    return true;
  }

  // Test hooks.
  void set_fail_writes(bool fail) { fail_writes_ = fail; }
  size_t write_count() const { return write_count_; }
  uint8_t* mutable_data() { return bytes_.data(); }

 private:
  std::array<uint8_t, kSize> bytes_{};
  bool fail_writes_ = false;
  size_t write_count_ = 0;
};

}  // namespace motwin::board
