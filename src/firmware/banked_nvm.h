// The module's EEPROM image on a microcontroller: two banks of a flash region, each a header and a
// whole copy of the image. A write fills the bank not in use (erase, program the payload, program
// the header last) and only then is that bank current, so a reset at any point of a write leaves
// the old image or the new one, both complete: the guarantee host::EepromFile gives with a
// temporary file and a rename (docs/firmware.md, "EEPROM image").
//
// Header (little-endian words): magic, sequence (the newer bank has the greater, modulo 2^32),
// payload size, CRC-32 of the payload. An erased bank (all 0xFF) or one with a bad CRC is not valid.
//
// The region is plain memory written with memset/memcpy: on the emulated board it is RAM outside
// the linked image. A board whose flash needs a controller would replace erase() and program().
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "board/non_volatile_memory.h"

namespace motwin::firmware {

// CRC-32 (IEEE 802.3, reflected, as zlib): bitwise, no table, for a firmware's flash budget.
constexpr uint32_t crc32(const uint8_t* bytes, size_t length) {
  uint32_t crc = 0xFFFFFFFFu;
  for (size_t i = 0; i < length; ++i) {
    crc ^= bytes[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

template <size_t kPayloadSize>
class BankedNvm final : public board::NonVolatileMemory {
 public:
  static constexpr uint32_t kMagic = 0x4545574Du;  // "MWEE"
  static constexpr size_t kHeaderSize = 16;
  // Each bank starts on a 4-byte boundary.
  static constexpr size_t kBankSize = (kHeaderSize + kPayloadSize + 3) / 4 * 4;
  static constexpr size_t kRegionSize = 2 * kBankSize;
  static constexpr uint8_t kErased = 0xFF;

  // `region` is kRegionSize bytes that keep their contents across a reset.
  explicit BankedNvm(uint8_t* region) : region_(region) {}

  // At power-up: the newer valid bank is the image. With none (a new board, or both damaged),
  // `format` fills a fresh payload with the factory image, which is then written. Returns whether
  // a valid image was found.
  template <class FormatFactoryImage>
  bool open(const FormatFactoryImage& format) {
    const bool valid0 = valid(0);
    const bool valid1 = valid(1);
    if (valid0 && valid1) {
      current_ = static_cast<int32_t>(sequence(1) - sequence(0)) > 0 ? 1 : 0;
    } else if (valid0 || valid1) {
      current_ = valid0 ? 0 : 1;
    } else {
      erase(0);
      format(payload(0), kPayloadSize);
      commit(0, 1);
      current_ = 0;
      return false;
    }
    return true;
  }

  size_t size() const override { return kPayloadSize; }
  const uint8_t* data() const override { return payload(current_); }

  bool write(size_t offset, const uint8_t* bytes, size_t length) override {
    if (offset > kPayloadSize || length > kPayloadSize - offset) return false;
    const size_t next = 1 - current_;
    erase(next);
    program(payload(next), payload(current_), kPayloadSize);
    program(payload(next) + offset, bytes, length);
    commit(next, sequence(current_) + 1);
    current_ = next;
    ++write_count_;
    return true;
  }

  size_t current_bank() const { return current_; }
  uint32_t write_count() const { return write_count_; }

  // The steps of write(), for the tests that cut it short as a reset would.
  uint8_t* bank(size_t index) { return region_ + index * kBankSize; }

 private:
  uint8_t* payload(size_t index) const { return region_ + index * kBankSize + kHeaderSize; }
  uint32_t word(size_t index, size_t field) const {
    uint32_t value;
    std::memcpy(&value, region_ + index * kBankSize + field * 4, 4);
    return value;
  }
  uint32_t sequence(size_t index) const { return word(index, 1); }
  bool valid(size_t index) const {
    return word(index, 0) == kMagic && word(index, 2) == kPayloadSize &&
           word(index, 3) == crc32(payload(index), kPayloadSize);
  }
  void erase(size_t index) { std::memset(region_ + index * kBankSize, kErased, kBankSize); }
  static void program(uint8_t* to, const uint8_t* from, size_t length) { std::memcpy(to, from, length); }
  // The header last: until it is written the bank is not valid.
  void commit(size_t index, uint32_t sequence_number) {
    const uint32_t header[4] = {kMagic, sequence_number, static_cast<uint32_t>(kPayloadSize),
                                crc32(payload(index), kPayloadSize)};
    program(region_ + index * kBankSize, reinterpret_cast<const uint8_t*>(header), kHeaderSize);
  }

  uint8_t* region_;
  size_t current_ = 0;
  uint32_t write_count_ = 0;
};

}  // namespace motwin::firmware
