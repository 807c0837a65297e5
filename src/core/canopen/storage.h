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
  bool application = false;
  uint8_t axis_mask = 0;  // bit n: motor n

  constexpr bool empty() const { return !communication && !node_settings && !application && axis_mask == 0; }

  constexpr bool contains(StorageGroup group, uint8_t axis) const {
    switch (group) {
      case StorageGroup::kNone: return false;
      case StorageGroup::kCommunication: return communication;
      case StorageGroup::kNodeSettings: return node_settings;
      case StorageGroup::kAxis: return axis < 8 && (axis_mask & (1u << axis)) != 0;
      case StorageGroup::kApplication: return application;
    }
    return false;
  }
};

// Store, restore and load over a module's dictionary. `scratch` (at least nvm.size() bytes) is
// where the new image is assembled before it goes to the NVM in one write, so that a failed write
// leaves the old image whole.
class ObjectStorage {
 public:
  ObjectStorage(RowDictionary& dictionary, board::NonVolatileMemory& nvm, uint8_t* scratch, size_t scratch_size)
      : dictionary_(dictionary), nvm_(nvm), scratch_(scratch), scratch_size_(scratch_size) {}

  // Saves the current values of the selected groups (1010). kHardware when the NVM write fails
  // (manual 3.1.7: 06060000), kOutOfMemory when the image is full.
  SdoAbort save(const StorageSelection& selection);
  // Removes the selected groups from the image (1011): their defaults apply at the next reset.
  SdoAbort restore_defaults(const StorageSelection& selection) { return commit(keep_unselected(selection)); }
  // Sets the selected objects to their stored values, or their defaults (reset, power-up).
  void load(const StorageSelection& selection);

 private:
  size_t capacity() const { return scratch_size_ < nvm_.size() ? scratch_size_ : nvm_.size(); }
  // `visit(info, ref)` for every stored numeric object the selection holds, each axis' copy; stops
  // at the first false (then returns false).
  template <class Visit>
  bool for_each_selected(const StorageSelection& selection, const Visit& visit);
  // Copies the records of the image that the selection does not touch into the scratch buffer.
  size_t keep_unselected(const StorageSelection& selection);
  SdoAbort commit(size_t count);

  RowDictionary& dictionary_;
  board::NonVolatileMemory& nvm_;
  uint8_t* scratch_;
  size_t scratch_size_;
};

}  // namespace motwin::canopen
