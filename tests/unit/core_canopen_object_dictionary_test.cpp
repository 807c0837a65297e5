// TableDictionary::find (src/core/canopen/object_dictionary.h): the binary search over the sorted
// row index gives exactly what the row-by-row search gives (find_linear): every row of the
// TMCM-3216 table at its index and sub-index for every axis, kNoObject / kNoSubIndex for every
// index and sub-index it does not have, the first row in table order where rows overlap, and the
// row-by-row fallback for tables beyond the index's capacity.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/canopen/object_dictionary.h"
#include "core/canopen/object_rows.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using canopen::Access;
using canopen::DataType;
using canopen::ObjectCode;
using canopen::ObjectRef;
using canopen::SdoAbort;

// find() and find_linear() agree on `index`/`sub`: the same abort, and when found the same row,
// axis and index.
template <class Dictionary>
void expect_same_as_linear(const Dictionary& dictionary, uint16_t index, uint8_t sub) {
  ObjectRef fast;
  ObjectRef linear;
  const SdoAbort fast_abort = dictionary.find(index, sub, fast);
  const SdoAbort linear_abort = dictionary.find_linear(index, sub, linear);
  ASSERT_EQ(fast_abort, linear_abort) << std::hex << index << " sub " << int(sub);
  if (fast_abort != SdoAbort::kNone) return;
  EXPECT_EQ(fast.info, linear.info) << std::hex << index << " sub " << int(sub);
  EXPECT_EQ(fast.row, linear.row) << std::hex << index << " sub " << int(sub);
  EXPECT_EQ(fast.index, linear.index);
  EXPECT_EQ(fast.axis, linear.axis) << std::hex << index << " sub " << int(sub);
}

// Every index 0000..FFFF: every sub-index of an index that exists, sub 0, 1 and FF of one that
// does not.
template <class Dictionary>
void expect_every_index_same_as_linear(const Dictionary& dictionary) {
  for (uint32_t index = 0; index <= 0xFFFF; ++index) {
    const auto i = static_cast<uint16_t>(index);
    ObjectRef ref;
    if (dictionary.find_linear(i, 0, ref) == SdoAbort::kNoObject) {
      for (const uint8_t sub : {0, 1, 0xFF}) expect_same_as_linear(dictionary, i, sub);
    } else {
      for (uint32_t sub = 0; sub <= 0xFF; ++sub) expect_same_as_linear(dictionary, i, static_cast<uint8_t>(sub));
    }
    if (::testing::Test::HasFailure()) return;  // one index is enough to see what is wrong
  }
}

TEST(TableDictionaryFind, tmcm3216_table_is_indexed) {
  Tmcm3216Rig rig;
  EXPECT_TRUE(rig.device->dictionary().indexed());
  EXPECT_LE(Tmcm3216::object_table().size(), Tmcm3216::Dictionary::kIndexCapacity);
}

TEST(TableDictionaryFind, every_tmcm3216_row_is_found_at_its_index_for_every_axis) {
  Tmcm3216Rig rig;
  const Tmcm3216::Dictionary& dictionary = rig.device->dictionary();
  const auto rows = dictionary.rows();
  size_t objects = 0;
  for (size_t row = 0; row < rows.size(); ++row) {
    const canopen::EntryInfo& info = rows[row].info;
    for (uint8_t axis = 0; axis < dictionary.axes_of(info); ++axis) {
      const auto index = static_cast<uint16_t>(info.index + axis * info.axis_stride);
      ObjectRef ref;
      ASSERT_EQ(dictionary.find(index, info.sub, ref), SdoAbort::kNone) << std::hex << index << " sub " << int(info.sub);
      EXPECT_EQ(ref.row, row) << std::hex << index << " sub " << int(info.sub);  // no two rows for one entry
      EXPECT_EQ(ref.info, &info);
      EXPECT_EQ(ref.index, index);
      EXPECT_EQ(ref.axis, info.axis_stride == 0 ? 0 : axis);
      ++objects;
    }
  }
  EXPECT_GT(objects, rows.size());  // the per-axis rows count three times
}

TEST(TableDictionaryFind, tmcm3216_absent_indices_and_sub_indices_abort_as_before) {
  Tmcm3216Rig rig;
  const Tmcm3216::Dictionary& dictionary = rig.device->dictionary();
  ObjectRef ref;
  EXPECT_EQ(dictionary.find(0x1234, 0, ref), SdoAbort::kNoObject);
  EXPECT_EQ(dictionary.find(0x1018, 5, ref), SdoAbort::kNoSubIndex);
  EXPECT_EQ(dictionary.find(0x1881, 7, ref), SdoAbort::kNoSubIndex);  // TPDO 2 of axis 2 has sub 0..5
  EXPECT_EQ(dictionary.find(0x14C0, 0, ref), SdoAbort::kNoObject);    // RPDO 1 of an axis 3
  EXPECT_EQ(dictionary.find(0x7840, 0, ref), SdoAbort::kNoObject);    // 6040 of an axis 3
  EXPECT_EQ(dictionary.find(0x6840, 1, ref), SdoAbort::kNoSubIndex);
  ASSERT_EQ(dictionary.find(0x7040, 0, ref), SdoAbort::kNone);
  EXPECT_EQ(ref.axis, 2);
  EXPECT_EQ(ref.info->index, 0x6040);
}

TEST(TableDictionaryFind, tmcm3216_every_index_and_sub_index_as_the_row_by_row_search) {
  Tmcm3216Rig rig;
  expect_every_index_same_as_linear(rig.device->dictionary());
}

// --- Tables made to overlap ------------------------------------------------------------------

struct Owner {};
using Row = canopen::EntryRow<Owner>;
namespace r = canopen::rows;

Row u8(uint16_t index, uint8_t sub, uint16_t stride = 0) {
  return r::per_axis<Owner>(r::row<Owner>(index, sub, ObjectCode::kRecord, "o", "e", DataType::kUnsigned8,
                                          Access::kRw, 0, 0xFF, 0),
                            stride);
}

TEST(TableDictionaryFind, overlapping_rows_give_the_first_in_table_order) {
  // 2020 sub 0 is a device-wide row, axis 1 of a stride-0x20 row... and axis 2 of a stride-0x10
  // row; the first in the table wins, as the row-by-row search has always done.
  const std::vector<Row> rows = {u8(0x2020, 0),        u8(0x2000, 0, 0x10), u8(0x2000, 1, 0x10),
                                 u8(0x2000, 0, 0x20),  u8(0x2000, 2, 0x20), u8(0x2040, 3),
                                 u8(0x1FF0, 0, 0x10),  u8(0x2041, 0, 0x800), u8(0x0000, 0, 0x10)};
  Owner owner;
  const canopen::TableDictionary<Owner> dictionary(owner, rows, 3);
  ASSERT_TRUE(dictionary.indexed());
  ObjectRef ref;
  ASSERT_EQ(dictionary.find(0x2020, 0, ref), SdoAbort::kNone);
  EXPECT_EQ(ref.row, 0u);
  ASSERT_EQ(dictionary.find(0x2020, 2, ref), SdoAbort::kNone);
  EXPECT_EQ(ref.row, 4u);
  EXPECT_EQ(ref.axis, 1);
  ASSERT_EQ(dictionary.find(0x2010, 0, ref), SdoAbort::kNone);  // 1FF0 axis 2 is later in the table
  EXPECT_EQ(ref.row, 1u);
  EXPECT_EQ(dictionary.find(0x2030, 0, ref), SdoAbort::kNoObject);
  EXPECT_EQ(dictionary.find(0x2040, 0, ref), SdoAbort::kNone);    // 2000 stride 0x20, axis 2
  EXPECT_EQ(dictionary.find(0x2040, 1, ref), SdoAbort::kNoSubIndex);
  for (uint32_t index = 0; index <= 0xFFFF; ++index) {
    for (const uint8_t sub : {0, 1, 2, 3, 4}) expect_same_as_linear(dictionary, static_cast<uint16_t>(index), sub);
    if (HasFailure()) return;
  }
}

TEST(TableDictionaryFind, one_axis_has_no_strided_objects_beyond_axis_0) {
  const std::vector<Row> rows = {u8(0x3000, 0, 0x100), u8(0x3100, 1)};
  Owner owner;
  const canopen::TableDictionary<Owner> dictionary(owner, rows, 1);
  ObjectRef ref;
  EXPECT_EQ(dictionary.find(0x3000, 0, ref), SdoAbort::kNone);
  EXPECT_EQ(dictionary.find(0x3100, 0, ref), SdoAbort::kNoSubIndex);
  EXPECT_EQ(dictionary.find(0x3200, 0, ref), SdoAbort::kNoObject);
  for (uint32_t index = 0x2F00; index <= 0x3300; ++index) expect_same_as_linear(dictionary, static_cast<uint16_t>(index), 0);
}

TEST(TableDictionaryFind, too_many_strides_fall_back_to_the_row_by_row_search) {
  std::vector<Row> rows;
  for (uint16_t s = 1; s <= canopen::TableDictionary<Owner>::kMaxStrides + 1; ++s) {
    rows.push_back(u8(static_cast<uint16_t>(0x4000 + s * 0x100), 0, static_cast<uint16_t>(s * 0x10)));
  }
  Owner owner;
  const canopen::TableDictionary<Owner> dictionary(owner, rows, 3);
  EXPECT_FALSE(dictionary.indexed());
  ObjectRef ref;
  ASSERT_EQ(dictionary.find(0x4120, 0, ref), SdoAbort::kNone);
  EXPECT_EQ(ref.axis, 2);
  EXPECT_EQ(dictionary.find(0x4130, 0, ref), SdoAbort::kNoObject);
}

TEST(TableDictionaryFind, a_table_beyond_the_index_capacity_falls_back_to_the_row_by_row_search) {
  std::vector<Row> rows;
  for (size_t i = 0; i <= canopen::TableDictionary<Owner>::kIndexCapacity; ++i) {
    rows.push_back(u8(static_cast<uint16_t>(0x5000 + i / 4), static_cast<uint8_t>(i % 4)));
  }
  Owner owner;
  const canopen::TableDictionary<Owner> dictionary(owner, rows, 3);
  EXPECT_FALSE(dictionary.indexed());
  ObjectRef ref;
  ASSERT_EQ(dictionary.find(0x5080, 0, ref), SdoAbort::kNone);
  EXPECT_EQ(ref.row, canopen::TableDictionary<Owner>::kIndexCapacity);
  EXPECT_EQ(dictionary.find(0x5080, 1, ref), SdoAbort::kNoSubIndex);
  EXPECT_EQ(dictionary.find(0x5081, 0, ref), SdoAbort::kNoObject);
}

}  // namespace
}  // namespace motwin::testing
