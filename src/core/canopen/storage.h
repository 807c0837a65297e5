// Store and restore of object values in the board's non-volatile memory (1010/1011, 2706), in
// the spirit of CANopenNode's storage/CO_storage: the image holds only what was saved, as
// self-describing records, so that adding objects to a table never invalidates a stored image.
//
// Image layout (little-endian):
//   0  4  magic "MWCO"
//   4  4  record count
//   8     records of 8 bytes: index u16, sub-index u8, reserved u8 (0), value u32
// An object missing from the image takes its default at the next reset. A record of an object
// that no longer exists is dropped at the next save.
#pragma once

#include <cstddef>
#include <cstdint>

#include "board/non_volatile_memory.h"
#include "core/canopen/object_dictionary.h"

namespace motwin::canopen {

struct StorageRecord {
  uint16_t index;
  uint8_t sub;
  uint32_t value;
};

// The byte format. Functions only: the bytes live in the NVM or in a caller's scratch buffer.
struct StorageImage {
  static constexpr uint32_t kMagic = 0x4F43'574D;  // "MWCO"
  static constexpr size_t kHeaderSize = 8;
  static constexpr size_t kRecordSize = 8;
  static constexpr size_t size_for(size_t records) { return kHeaderSize + records * kRecordSize; }

  // An empty image (every object at its default).
  static void format(uint8_t* image, size_t size);
  // Magic right and the records fit in `size`.
  static bool valid(const uint8_t* image, size_t size);
  static size_t count(const uint8_t* image);
  static void set_count(uint8_t* image, size_t count);
  static StorageRecord record(const uint8_t* image, size_t i);
  static void put_record(uint8_t* image, size_t i, const StorageRecord& record);
  // false when the image is invalid or holds no record of the object.
  static bool find(const uint8_t* image, size_t size, uint16_t index, uint8_t sub, uint32_t& value);
};

// Which groups a 1010/1011 sub-index (or 2706) selects.
struct StorageSelection {
  bool communication = false;
  bool node_settings = false;
  uint8_t axis_mask = 0;  // bit n: motor n

  constexpr bool contains(StorageGroup group, uint8_t axis) const {
    switch (group) {
      case StorageGroup::kNone: return false;
      case StorageGroup::kCommunication: return communication;
      case StorageGroup::kNodeSettings: return node_settings;
      case StorageGroup::kAxis: return axis < 8 && (axis_mask & (1u << axis)) != 0;
    }
    return false;
  }
};

// Store, restore and load over a TableDictionary. `scratch` (at least nvm.size() bytes) is where
// the new image is assembled before it goes to the NVM in one write, so that a failed write
// leaves the old image whole.
template <class Owner>
class ObjectStorage {
 public:
  ObjectStorage(TableDictionary<Owner>& dictionary, board::NonVolatileMemory& nvm, uint8_t* scratch,
                size_t scratch_size)
      : dictionary_(dictionary), nvm_(nvm), scratch_(scratch), scratch_size_(scratch_size) {}

  // Saves the current values of the selected groups (1010). kHardware when the NVM write fails
  // (manual 3.1.7: 06060000), kOutOfMemory when the image is full.
  SdoAbort save(const StorageSelection& selection) {
    size_t count = keep_unselected(selection);
    const auto rows = dictionary_.rows();
    for (size_t row = 0; row < rows.size(); ++row) {
      const EntryInfo& info = rows[row].info;
      if (info.storage == StorageGroup::kNone || !is_numeric(info.type)) continue;
      for (uint8_t axis = 0; axis < dictionary_.axes_of(info); ++axis) {
        if (!selection.contains(info.storage, axis)) continue;
        const ObjectRef ref = dictionary_.ref(row, axis);
        const int64_t value = dictionary_.value(ref);
        // "$NODEID+" objects at their default follow the node ID: nothing to store.
        if (info.default_plus_node_id && value == dictionary_.default_value(info, axis)) continue;
        if (StorageImage::size_for(count + 1) > capacity()) return SdoAbort::kOutOfMemory;
        StorageImage::put_record(scratch_, count++, StorageRecord{ref.index, info.sub, static_cast<uint32_t>(value)});
      }
    }
    return commit(count);
  }

  // Removes the selected groups from the image (1011): their defaults apply at the next reset.
  SdoAbort restore_defaults(const StorageSelection& selection) { return commit(keep_unselected(selection)); }

  // Sets the selected objects to their stored values, or their defaults (reset, power-up).
  void load(const StorageSelection& selection) {
    const uint8_t* image = nvm_.data();
    const size_t size = nvm_.size();
    const auto rows = dictionary_.rows();
    for (size_t row = 0; row < rows.size(); ++row) {
      const EntryInfo& info = rows[row].info;
      if (info.storage == StorageGroup::kNone || !is_numeric(info.type)) continue;
      for (uint8_t axis = 0; axis < dictionary_.axes_of(info); ++axis) {
        if (!selection.contains(info.storage, axis)) continue;
        const ObjectRef ref = dictionary_.ref(row, axis);
        uint32_t stored = 0;
        int64_t value = dictionary_.default_value(info, axis);
        if (StorageImage::find(image, size, ref.index, info.sub, stored)) {
          value = is_signed(info.type) ? static_cast<int32_t>(stored) : static_cast<int64_t>(stored);
          // A damaged or foreign record never puts an object out of its range.
          if (check_range(info, value) != SdoAbort::kNone) value = dictionary_.default_value(info, axis);
        }
        dictionary_.store(ref, value);
      }
    }
  }

 private:
  size_t capacity() const { return scratch_size_ < nvm_.size() ? scratch_size_ : nvm_.size(); }

  // Copies the records of the image that the selection does not touch into the scratch buffer.
  size_t keep_unselected(const StorageSelection& selection) {
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

  SdoAbort commit(size_t count) {
    StorageImage::format(scratch_, StorageImage::kHeaderSize);
    StorageImage::set_count(scratch_, count);
    return nvm_.write(0, scratch_, StorageImage::size_for(count)) ? SdoAbort::kNone : SdoAbort::kHardware;
  }

  TableDictionary<Owner>& dictionary_;
  board::NonVolatileMemory& nvm_;
  uint8_t* scratch_;
  size_t scratch_size_;
};

}  // namespace motwin::canopen
