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

template <class Visit>
bool ObjectStorage::for_each_selected(const StorageSelection& selection, const Visit& visit) {
  for (size_t row = 0; row < dictionary_.row_count(); ++row) {
    const EntryInfo& info = dictionary_.row_info(row);
    if (info.storage == StorageGroup::kNone || !is_numeric(info.type)) continue;
    for (uint8_t axis = 0; axis < dictionary_.axes_of(info); ++axis) {
      if (!selection.contains(info.storage, axis)) continue;
      if (!visit(info, dictionary_.ref(row, axis))) return false;
    }
  }
  return true;
}

SdoAbort ObjectStorage::save(const StorageSelection& selection) {
  size_t count = keep_unselected(selection);
  const bool fits = for_each_selected(selection, [&](const EntryInfo& info, const ObjectRef& ref) {
    const int64_t value = dictionary_.value(ref);
    // "$NODEID+" objects at their default follow the node ID: nothing to store.
    if (info.default_plus_node_id && value == dictionary_.default_value(info, ref.axis)) return true;
    if (StorageImage::size_for(count + 1) > capacity()) return false;
    StorageImage::put_record(scratch_, count++, StorageRecord{ref.index, info.sub, static_cast<uint32_t>(value)});
    return true;
  });
  return fits ? commit(count) : SdoAbort::kOutOfMemory;
}

void ObjectStorage::load(const StorageSelection& selection) {
  const uint8_t* image = nvm_.data();
  const size_t size = nvm_.size();
  for_each_selected(selection, [&](const EntryInfo& info, const ObjectRef& ref) {
    uint32_t stored = 0;
    int64_t value = dictionary_.default_value(info, ref.axis);
    if (StorageImage::find(image, size, ref.index, info.sub, stored)) {
      value = is_signed(info.type) ? static_cast<int32_t>(stored) : static_cast<int64_t>(stored);
      // A damaged or foreign record never puts an object out of its range.
      if (check_range(info, value) != SdoAbort::kNone) value = dictionary_.default_value(info, ref.axis);
    }
    dictionary_.store(ref, value);
    return true;
  });
}

size_t ObjectStorage::keep_unselected(const StorageSelection& selection) {
  const uint8_t* image = nvm_.data();
  size_t kept = 0;
  if (StorageImage::valid(image, nvm_.size())) {
    const size_t n = StorageImage::count(image);
    for (size_t i = 0; i < n; ++i) {
      const StorageRecord record = StorageImage::record(image, i);
      ObjectRef ref;
      if (dictionary_.find(record.index, record.sub, ref) != SdoAbort::kNone) continue;
      if (ref.info->storage == StorageGroup::kNone || selection.contains(ref.info->storage, ref.axis)) continue;
      if (StorageImage::size_for(kept + 1) > capacity()) break;
      StorageImage::put_record(scratch_, kept++, record);
    }
  }
  return kept;
}

SdoAbort ObjectStorage::commit(size_t count) {
  StorageImage::format(scratch_, StorageImage::kHeaderSize);
  StorageImage::set_count(scratch_, count);
  return nvm_.write(0, scratch_, StorageImage::size_for(count)) ? SdoAbort::kNone : SdoAbort::kHardware;
}

}  // namespace motwin::canopen
