// The CANopen object dictionary: every object a master can reach by index and sub-index,
// described as data (docs/architecture.md "Principles"). A module lists its objects
// as EntryRow tables, one row per sub-index with the manual's columns: index, sub-index, names,
// data type, access (ro/wo/rw/const), PDO mapping, value range and default. Rows bind to the
// module's typed state with small function pointers, the way params::ParameterRow does for TMCL.
//
// Multi-axis modules (TMCM-3216 manual 2.6.1): a row with axis_stride != 0 describes one object
// per axis, axis n at index + n * axis_stride (0x200 manufacturer area, 0x800 profile area,
// 0x40 PDO parameters).
//
// The SDO server and the PDOs reach every object through the one ObjectDictionary interface, as
// CANopenNode's OD interface does. A TableDictionary finds an index/sub-index by binary search in
// an index of its rows that its constructor sorts once (fixed capacity, no heap).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>

#include "core/canopen/sdo_abort.h"

namespace motwin::canopen {

// CiA-301 data type indices (they are also the EDS DataType values).
enum class DataType : uint8_t {
  kBoolean = 0x01,
  kInteger8 = 0x02,
  kInteger16 = 0x03,
  kInteger32 = 0x04,
  kUnsigned8 = 0x05,
  kUnsigned16 = 0x06,
  kUnsigned32 = 0x07,
  kVisibleString = 0x09,
};

// Size in bytes of a numeric type; 0 for a visible string (its size is its current length).
constexpr uint8_t type_size(DataType type) {
  switch (type) {
    case DataType::kBoolean:
    case DataType::kInteger8:
    case DataType::kUnsigned8: return 1;
    case DataType::kInteger16:
    case DataType::kUnsigned16: return 2;
    case DataType::kInteger32:
    case DataType::kUnsigned32: return 4;
    case DataType::kVisibleString: return 0;
  }
  return 0;
}
constexpr bool is_signed(DataType type) {
  return type == DataType::kInteger8 || type == DataType::kInteger16 || type == DataType::kInteger32;
}
constexpr bool is_numeric(DataType type) { return type_size(type) != 0; }

enum class Access : uint8_t { kRo, kWo, kRw, kConst };
constexpr bool readable(Access access) { return access != Access::kWo; }
constexpr bool writable(Access access) { return access == Access::kWo || access == Access::kRw; }

// CiA-306 object codes.
enum class ObjectCode : uint8_t { kVar = 7, kArray = 8, kRecord = 9 };

// What 1010/1011 sub-indices (and 2706) save and restore. See docs/canopen.md "Storage".
enum class StorageGroup : uint8_t {
  kNone,           // not stored (constants, live values, actions)
  kCommunication,  // 1005..1029, PDO parameters: saved by 1010 sub 1 only
  kNodeSettings,   // 2704 bit rate, 2705 node ID: 1010 sub 1 and 2, 2706 sub 1
  kAxis,           // motor n parameters: 1010 sub 1 and sub 4 + n
  kApplication,    // device-wide application objects (TMCM-1636: the manufacturer area, 1010 sub 3)
};

// One sub-index as the manual's entry-description tables give it. Pure data.
struct EntryInfo {
  uint16_t index;
  uint8_t sub;
  ObjectCode code;
  std::string_view object_name;  // name of the index ("Identity Object")
  std::string_view name;         // name of the sub-index ("Vendor ID"); a VAR repeats object_name
  DataType type;
  Access access;
  bool pdo_mappable;
  int64_t min;                   // value range of numeric entries (unsigned 32-bit fits)
  int64_t max;
  int64_t default_value;
  bool default_plus_node_id;     // EDS "$NODEID+default": 1014, PDO COB-IDs
  uint16_t axis_stride;          // 0: one object for the device
  StorageGroup storage;
  // nullptr: every axis has default_value; else the default of each axis (PDO mappings of
  // axis n name the objects of axis n; PDOs of axes 1 and 2 start disabled).
  int64_t (*axis_default)(uint8_t axis);
};

// An entry found by index and sub-index: the row, the axis and the index that was asked for.
struct ObjectRef {
  const EntryInfo* info = nullptr;
  size_t row = 0;
  uint16_t index = 0;
  uint8_t axis = 0;
};

class ObjectDictionary {
 public:
  // kNoObject when no object has this index, kNoSubIndex when it has no such sub-index.
  virtual SdoAbort find(uint16_t index, uint8_t sub, ObjectRef& out) const = 0;
  // Size of the current value in bytes: the type's size, or a string's length.
  virtual size_t size(const ObjectRef& ref) = 0;
  // The value as an SDO upload sends it (little-endian); kWriteOnly for a wo entry.
  virtual SdoAbort read(const ObjectRef& ref, uint8_t* out, size_t capacity, size_t& length) = 0;
  // A write as an SDO download makes it: access, size (kDataTooLong/kDataTooShort), range
  // (kValueTooHigh/kValueTooLow) and the object's own checks, then the value is stored.
  virtual SdoAbort write(const ObjectRef& ref, const uint8_t* data, size_t length) = 0;
  // Part of a value longer than the SDO server's buffer (a large DOMAIN), `capacity` bytes
  // from `offset` on (fewer at the end), so that uploads of any size stream through a fixed
  // buffer. Objects that fit the buffer never get here; the default refuses (05040005).
  virtual SdoAbort read_part(const ObjectRef& ref, size_t offset, uint8_t* out, size_t capacity, size_t& length) {
    (void)ref;
    (void)offset;
    (void)out;
    (void)capacity;
    length = 0;
    return SdoAbort::kOutOfMemory;
  }

 protected:
  ~ObjectDictionary() = default;
};

// A dictionary made of rows (EntryInfo), as every module's is: what the services that walk every
// object (storage, the node's resets) and the "$NODEID+" defaults need besides lookup and access.
class RowDictionary : public ObjectDictionary {
 public:
  // The rows in table order.
  virtual size_t row_count() const = 0;
  virtual const EntryInfo& row_info(size_t row) const = 0;
  // The current value of a numeric entry, whatever its access.
  virtual int64_t value(const ObjectRef& ref) = 0;
  // Stores without the SDO checks: defaults and stored values at reset.
  virtual void store(const ObjectRef& ref, int64_t new_value) = 0;

  uint8_t axis_count() const { return axis_count_; }
  // The node ID that "$NODEID+" defaults add.
  void set_node_id(uint8_t node_id) { node_id_ = node_id; }
  uint8_t node_id() const { return node_id_; }

  int64_t default_value(const EntryInfo& info, uint8_t axis) const {
    const int64_t base = info.axis_default != nullptr ? info.axis_default(axis) : info.default_value;
    return info.default_plus_node_id ? base + node_id_ : base;
  }
  // The reference of row `row` for `axis` (axis 0 for device-wide rows).
  ObjectRef ref(size_t row, uint8_t axis) const {
    const EntryInfo& info = row_info(row);
    const uint8_t a = info.axis_stride == 0 ? 0 : axis;
    return ObjectRef{&info, row, static_cast<uint16_t>(info.index + a * info.axis_stride), a};
  }
  uint8_t axes_of(const EntryInfo& info) const { return info.axis_stride == 0 ? 1 : axis_count_; }

 protected:
  explicit RowDictionary(uint8_t axis_count) : axis_count_(axis_count) {}
  ~RowDictionary() = default;

 private:
  uint8_t axis_count_;
  uint8_t node_id_ = 1;
};

// Little-endian codec of numeric values: two's complement, sign-extended when read back.
void encode_value(DataType type, int64_t value, uint8_t* out);
int64_t decode_value(DataType type, const uint8_t* data);
// kNone, kValueTooHigh or kValueTooLow.
SdoAbort check_range(const EntryInfo& info, int64_t value);
// Whether `index` names the object of `info` for some axis below axis_count; sets `axis`.
bool index_matches(const EntryInfo& info, uint16_t index, uint8_t axis_count, uint8_t& axis);

// How a row reaches the module's state. Owner is the module profile.
template <class Owner>
struct EntryBinding {
  // nullptr: the entry is the row's constant default (plus the node ID where flagged).
  int64_t (*get)(Owner& owner, uint8_t axis) = nullptr;
  // Stores a value already checked against the row's range (and `check` for SDO writes). Used
  // for SDO writes, for loading defaults and stored values at reset, and for actions (1010).
  SdoAbort (*set)(Owner& owner, uint8_t axis, int64_t value) = nullptr;
  // Extra checks of an SDO write, without side effects: PDO rules, allowed value sets.
  SdoAbort (*check)(Owner& owner, uint8_t axis, int64_t value) = nullptr;
  // Visible strings.
  std::string_view (*get_string)(Owner& owner, uint8_t axis) = nullptr;
};

template <class Owner>
struct EntryRow {
  EntryInfo info;
  EntryBinding<Owner> binding;
};

// A binding to one plain field: `Ref` is a captureless lambda `(Owner&, uint8_t axis) -> T&`.
template <class Owner, auto Ref>
constexpr EntryBinding<Owner> field_binding() {
  EntryBinding<Owner> binding;
  binding.get = [](Owner& owner, uint8_t axis) { return static_cast<int64_t>(Ref(owner, axis)); };
  binding.set = [](Owner& owner, uint8_t axis, int64_t value) {
    auto& field = Ref(owner, axis);
    field = static_cast<std::remove_reference_t<decltype(field)>>(value);
    return SdoAbort::kNone;
  };
  return binding;
}

// The dictionary over a module's row table.
template <class Owner>
class TableDictionary final : public RowDictionary {
 public:
  // Rows the lookup index holds, and distinct axis strides it handles. A table beyond either is
  // searched row by row: the same answers, only slower (indexed() says which).
  static constexpr size_t kIndexCapacity = 512;
  static constexpr size_t kMaxStrides = 4;

  TableDictionary(Owner& owner, std::span<const EntryRow<Owner>> rows, uint8_t axis_count)
      : RowDictionary(axis_count), owner_(owner), rows_(rows) {
    build_index();
  }
  TableDictionary(const TableDictionary&) = delete;
  TableDictionary& operator=(const TableDictionary&) = delete;

  std::span<const EntryRow<Owner>> rows() const { return rows_; }
  size_t row_count() const override { return rows_.size(); }
  const EntryInfo& row_info(size_t row) const override { return rows_[row].info; }

  // The first row in table order that is `index`/`sub` for some axis. By binary search over the
  // rows sorted by base index: an object of axis n has its row n strides below `index`, so the
  // candidates are the rows at `index` itself and at `index - n * stride` for each distinct
  // stride of the table; each candidate is then matched exactly as find_linear() matches it.
  SdoAbort find(uint16_t index, uint8_t sub, ObjectRef& out) const override {
    if (!indexed_) return find_linear(index, sub, out);
    Match match;
    match_base(index, index, sub, match);
    for (size_t s = 0; s < stride_count_; ++s) {
      for (uint32_t n = 1; n < axis_count(); ++n) {
        const uint32_t below = n * strides_[s];
        if (below <= index) match_base(static_cast<uint16_t>(index - below), index, sub, match);
      }
    }
    if (match.row == kNoRow) return match.index_found ? SdoAbort::kNoSubIndex : SdoAbort::kNoObject;
    out = ObjectRef{&rows_[match.row].info, match.row, index, match.axis};
    return SdoAbort::kNone;
  }
  // Every row in table order: what find() answers without the index (tables beyond its capacity,
  // and the reference the tests hold find() to).
  SdoAbort find_linear(uint16_t index, uint8_t sub, ObjectRef& out) const {
    bool index_found = false;
    for (size_t i = 0; i < rows_.size(); ++i) {
      uint8_t axis = 0;
      if (!index_matches(rows_[i].info, index, axis_count(), axis)) continue;
      index_found = true;
      if (rows_[i].info.sub != sub) continue;
      out = ObjectRef{&rows_[i].info, i, index, axis};
      return SdoAbort::kNone;
    }
    return index_found ? SdoAbort::kNoSubIndex : SdoAbort::kNoObject;
  }
  // Whether find() uses the sorted index (false: the table exceeds kIndexCapacity or kMaxStrides).
  bool indexed() const { return indexed_; }

  size_t size(const ObjectRef& ref) override {
    if (is_numeric(ref.info->type)) return type_size(ref.info->type);
    const auto& binding = rows_[ref.row].binding;
    return binding.get_string ? binding.get_string(owner_, ref.axis).size() : 0;
  }

  SdoAbort read(const ObjectRef& ref, uint8_t* out, size_t capacity, size_t& length) override {
    length = 0;
    if (!readable(ref.info->access)) return SdoAbort::kWriteOnly;
    if (is_numeric(ref.info->type)) {
      if (capacity < type_size(ref.info->type)) return SdoAbort::kOutOfMemory;
      encode_value(ref.info->type, value(ref), out);
      length = type_size(ref.info->type);
      return SdoAbort::kNone;
    }
    const auto& binding = rows_[ref.row].binding;
    const std::string_view text = binding.get_string ? binding.get_string(owner_, ref.axis) : std::string_view{};
    if (text.size() > capacity) return SdoAbort::kOutOfMemory;
    for (size_t i = 0; i < text.size(); ++i) out[i] = static_cast<uint8_t>(text[i]);
    length = text.size();
    return SdoAbort::kNone;
  }

  SdoAbort write(const ObjectRef& ref, const uint8_t* data, size_t length) override {
    const EntryInfo& info = *ref.info;
    const auto& binding = rows_[ref.row].binding;
    if (!writable(info.access) || binding.set == nullptr) return SdoAbort::kReadOnly;
    if (!is_numeric(info.type)) return SdoAbort::kUnsupportedAccess;  // no writable strings yet
    if (length > type_size(info.type)) return SdoAbort::kDataTooLong;
    if (length < type_size(info.type)) return SdoAbort::kDataTooShort;
    const int64_t new_value = decode_value(info.type, data);
    if (const SdoAbort abort = check_range(info, new_value); abort != SdoAbort::kNone) return abort;
    if (binding.check != nullptr) {
      if (const SdoAbort abort = binding.check(owner_, ref.axis, new_value); abort != SdoAbort::kNone) return abort;
    }
    return binding.set(owner_, ref.axis, new_value);
  }

  int64_t value(const ObjectRef& ref) override {
    const auto& binding = rows_[ref.row].binding;
    return binding.get ? binding.get(owner_, ref.axis) : default_value(*ref.info, ref.axis);
  }
  void store(const ObjectRef& ref, int64_t new_value) override {
    const auto& binding = rows_[ref.row].binding;
    if (binding.set != nullptr) binding.set(owner_, ref.axis, new_value);
  }

 private:
  static constexpr size_t kNoRow = ~size_t{0};
  struct Match {
    size_t row = kNoRow;  // the lowest matching row so far
    uint8_t axis = 0;
    bool index_found = false;
  };

  // Sorts the row numbers by (base index, sub-index, row) once; rows_ never changes afterwards.
  void build_index() {
    if (rows_.size() > kIndexCapacity) return;
    for (size_t i = 0; i < rows_.size(); ++i) {
      const uint16_t stride = rows_[i].info.axis_stride;
      if (stride == 0) continue;
      bool known = false;
      for (size_t s = 0; s < stride_count_; ++s) known = known || strides_[s] == stride;
      if (known) continue;
      if (stride_count_ == kMaxStrides) return;
      strides_[stride_count_++] = stride;
    }
    // Insertion sort: a few hundred rows, once, at start-up.
    for (size_t i = 0; i < rows_.size(); ++i) {
      size_t k = i;
      while (k > 0 && sorts_before(i, order_[k - 1])) {
        order_[k] = order_[k - 1];
        --k;
      }
      order_[k] = static_cast<uint16_t>(i);
    }
    indexed_ = true;
  }
  bool sorts_before(size_t a, size_t b) const {
    const EntryInfo& x = rows_[a].info;
    const EntryInfo& y = rows_[b].info;
    if (x.index != y.index) return x.index < y.index;
    if (x.sub != y.sub) return x.sub < y.sub;
    return a < b;
  }
  // The rows whose base index is `base`, matched against the asked-for `index` and `sub`.
  void match_base(uint16_t base, uint16_t index, uint8_t sub, Match& match) const {
    size_t low = 0;
    size_t high = rows_.size();
    while (low < high) {  // first sorted position with a base index >= base
      const size_t mid = low + (high - low) / 2;
      if (rows_[order_[mid]].info.index < base) {
        low = mid + 1;
      } else {
        high = mid;
      }
    }
    for (size_t k = low; k < rows_.size() && rows_[order_[k]].info.index == base; ++k) {
      const size_t row = order_[k];
      uint8_t axis = 0;
      if (!index_matches(rows_[row].info, index, axis_count(), axis)) continue;
      match.index_found = true;
      if (rows_[row].info.sub == sub && row < match.row) {
        match.row = row;
        match.axis = axis;
      }
    }
  }

  Owner& owner_;
  std::span<const EntryRow<Owner>> rows_;
  // The lookup index, built by the constructor (no heap): row numbers sorted by base index and
  // the table's distinct non-zero axis strides.
  uint16_t order_[kIndexCapacity] = {};
  uint16_t strides_[kMaxStrides] = {};
  size_t stride_count_ = 0;
  bool indexed_ = false;
};

}  // namespace motwin::canopen
