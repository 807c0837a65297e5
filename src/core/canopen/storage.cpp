#include "core/canopen/storage.h"

namespace motwin::canopen {
namespace {

uint32_t get_u32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}
void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}

}  // namespace

void StorageImage::format(uint8_t* image, size_t size) {
  for (size_t i = 0; i < size; ++i) image[i] = 0;
  if (size >= kHeaderSize) put_u32(image, kMagic);
}

bool StorageImage::valid(const uint8_t* image, size_t size) {
  if (size < kHeaderSize || get_u32(image) != kMagic) return false;
  return count(image) <= (size - kHeaderSize) / kRecordSize;
}

size_t StorageImage::count(const uint8_t* image) { return get_u32(image + 4); }

void StorageImage::set_count(uint8_t* image, size_t count) { put_u32(image + 4, static_cast<uint32_t>(count)); }

StorageRecord StorageImage::record(const uint8_t* image, size_t i) {
  const uint8_t* p = image + kHeaderSize + i * kRecordSize;
  return StorageRecord{static_cast<uint16_t>(p[0] | p[1] << 8), p[2], get_u32(p + 4)};
}

void StorageImage::put_record(uint8_t* image, size_t i, const StorageRecord& record) {
  uint8_t* p = image + kHeaderSize + i * kRecordSize;
  p[0] = static_cast<uint8_t>(record.index);
  p[1] = static_cast<uint8_t>(record.index >> 8);
  p[2] = record.sub;
  p[3] = 0;
  put_u32(p + 4, record.value);
}

bool StorageImage::find(const uint8_t* image, size_t size, uint16_t index, uint8_t sub, uint32_t& value) {
  if (!valid(image, size)) return false;
  const size_t n = count(image);
  for (size_t i = 0; i < n; ++i) {
    const StorageRecord r = record(image, i);
    if (r.index == index && r.sub == sub) {
      value = r.value;
      return true;
    }
  }
  return false;
}

}  // namespace motwin::canopen
