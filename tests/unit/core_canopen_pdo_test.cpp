// PDOs (src/core/canopen/pdo.h) and SYNC (sync.h): the PDO service on a test dictionary with
// mappable objects (RPDO writes, TPDO change events, inhibit time, event timer, synchronous
// counting, RPDO-before-TPDO at a SYNC), and the TMCM-3216 profile: python-canopen's mapping
// procedure with its refusals, first transmission on entering operational, EMCY 8210/8220, the
// SYNC consumer and the SYNC producer (1005 bit 30, 1006).
#include <gtest/gtest.h>

#include <vector>

#include "core/canopen/pdo.h"
#include "core/canopen/sync.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using canopen::DataType;
using canopen::EntryInfo;
using canopen::ObjectRef;
using canopen::PdoCommunication;
using canopen::PdoMapping;
using canopen::PdoService;
using canopen::RpdoReception;
using canopen::SdoAbort;

// 2000 UNSIGNED16 rw, 2001 INTEGER32 rw with range -1000..1000, 2002 UNSIGNED8 ro.
class ValueDictionary final : public canopen::ObjectDictionary {
 public:
  int64_t values[3] = {0, 0, 0};

  SdoAbort find(uint16_t index, uint8_t sub, ObjectRef& out) const override {
    ++finds;
    if (index < 0x2000 || index > 0x2002) return SdoAbort::kNoObject;
    if (sub != 0) return SdoAbort::kNoSubIndex;
    out = ObjectRef{&kInfo[index - 0x2000], static_cast<size_t>(index - 0x2000), index, 0};
    return SdoAbort::kNone;
  }
  size_t size(const ObjectRef& ref) override { return canopen::type_size(ref.info->type); }
  SdoAbort read(const ObjectRef& ref, uint8_t* out, size_t capacity, size_t& length) override {
    length = canopen::type_size(ref.info->type);
    if (capacity < length) return SdoAbort::kOutOfMemory;
    canopen::encode_value(ref.info->type, values[ref.row], out);
    return SdoAbort::kNone;
  }
  SdoAbort write(const ObjectRef& ref, const uint8_t* data, size_t length) override {
    if (!canopen::writable(ref.info->access)) return SdoAbort::kReadOnly;
    if (length != canopen::type_size(ref.info->type)) return SdoAbort::kTypeMismatch;
    const int64_t v = canopen::decode_value(ref.info->type, data);
    if (const SdoAbort a = canopen::check_range(*ref.info, v); a != SdoAbort::kNone) return a;
    values[ref.row] = v;
    ++writes;
    return SdoAbort::kNone;
  }
  int writes = 0;
  mutable int finds = 0;  // the PDOs resolve a mapping once, not at every frame

 private:
  static const EntryInfo kInfo[3];
};

constexpr EntryInfo value_info(uint16_t index, DataType type, canopen::Access access, int64_t min, int64_t max) {
  return EntryInfo{index, 0, canopen::ObjectCode::kVar, "v", "v", type, access, true, min, max, 0, false, 0,
                   canopen::StorageGroup::kNone, nullptr};
}
const EntryInfo ValueDictionary::kInfo[3] = {
    value_info(0x2000, DataType::kUnsigned16, canopen::Access::kRw, 0, 0xFFFF),
    value_info(0x2001, DataType::kInteger32, canopen::Access::kRw, -1000, 1000),
    value_info(0x2002, DataType::kUnsigned8, canopen::Access::kRo, 0, 0xFF),
};

struct PdoRig {
  ValueDictionary dictionary;
  RecordingCanController can;
  PdoCommunication rpdo[2] = {{0x201, 0xFF, 0, 0}, {0x301, 1, 0, 0}};
  PdoMapping rpdo_mapping[2] = {{2, {0x2000'0010, 0x2001'0020}}, {1, {0x2000'0010}}};
  PdoCommunication tpdo[2] = {{0x181, 0xFF, 0, 0}, {0x281, 2, 0, 0}};
  PdoMapping tpdo_mapping[2] = {{2, {0x2000'0010, 0x2002'0008}}, {2, {0x2000'0010, 0x0005'0008}}};
  PdoService pdos{dictionary, can, rpdo, rpdo_mapping, tpdo, tpdo_mapping};

  std::vector<can::CanFrame> frames_on(uint32_t id) {
    std::vector<can::CanFrame> out;
    for (const can::CanFrame& f : can.take()) {
      if (f.id == id) out.push_back(f);
    }
    return out;
  }
};

TEST(Pdo, rpdo_writes_every_mapped_object_with_its_length) {
  PdoRig rig;
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x34, 0x12, 0x18, 0xFC, 0xFF, 0xFF})), RpdoReception::kAccepted);
  EXPECT_EQ(rig.dictionary.values[0], 0x1234);
  EXPECT_EQ(rig.dictionary.values[1], -1000);
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x202, {1, 2})), RpdoReception::kNotPdo);
}

TEST(Pdo, rpdo_too_short_writes_nothing_and_too_long_writes_the_mapped_bytes) {
  PdoRig rig;
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x34, 0x12, 0x05, 0x00, 0x00})), RpdoReception::kTooShort);
  EXPECT_EQ(rig.dictionary.writes, 0);
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x34, 0x12, 0x05, 0x00, 0x00, 0x00, 0xAA})), RpdoReception::kTooLong);
  EXPECT_EQ(rig.dictionary.values[0], 0x1234);
  EXPECT_EQ(rig.dictionary.values[1], 5);
}

TEST(Pdo, rpdo_value_out_of_range_is_dropped_and_the_others_written) {
  PdoRig rig;
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x01, 0x00, 0xE9, 0x03, 0x00, 0x00})), RpdoReception::kAccepted);
  EXPECT_EQ(rig.dictionary.values[0], 1);
  EXPECT_EQ(rig.dictionary.values[1], 0);  // 1001 > 1000
}

TEST(Pdo, invalid_rpdo_is_ignored) {
  PdoRig rig;
  rig.rpdo[0].cob_id |= canopen::kPdoCobIdInvalid;
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {1, 0, 0, 0, 0, 0})), RpdoReception::kNotPdo);
  EXPECT_EQ(rig.dictionary.writes, 0);
}

TEST(Pdo, synchronous_rpdo_is_written_at_the_sync_before_tpdos_are_sampled) {
  PdoRig rig;
  rig.pdos.enter_operational();
  rig.can.take();
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x301, {0x11, 0x00})), RpdoReception::kAccepted);
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x301, {0x22, 0x00})), RpdoReception::kAccepted);  // the latest wins
  EXPECT_EQ(rig.dictionary.values[0], 0);
  rig.pdos.on_sync();  // TPDO 2 counts 1 of 2
  EXPECT_EQ(rig.dictionary.values[0], 0x22);
  EXPECT_TRUE(rig.frames_on(0x281).empty());
  rig.pdos.on_frame(frame_of(0x301, {0x33, 0x00}));
  rig.pdos.on_sync();  // count 2: sampled after the RPDO was written
  const auto tpdo = rig.frames_on(0x281);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].dlc, 3);
  EXPECT_EQ(tpdo[0].data[0], 0x33);
  EXPECT_EQ(tpdo[0].data[1], 0x00);
  EXPECT_EQ(tpdo[0].data[2], 0x00);  // dummy byte
  int sent = 0;
  for (int i = 0; i < 10; ++i) {
    rig.pdos.on_sync();
    sent += static_cast<int>(rig.frames_on(0x281).size());
  }
  EXPECT_EQ(sent, 5);  // every second SYNC
}

TEST(Pdo, event_driven_tpdo_goes_out_on_entering_operational_and_on_change) {
  PdoRig rig;
  rig.dictionary.values[0] = 0xBEEF;
  rig.dictionary.values[2] = 7;
  rig.pdos.enter_operational();
  rig.pdos.process(0);
  auto tpdo = rig.frames_on(0x181);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].dlc, 3);
  EXPECT_EQ(tpdo[0].data[0], 0xEF);
  EXPECT_EQ(tpdo[0].data[1], 0xBE);
  EXPECT_EQ(tpdo[0].data[2], 7);
  for (int i = 0; i < 100; ++i) rig.pdos.process(1000);
  EXPECT_TRUE(rig.frames_on(0x181).empty());  // no change, no event timer
  rig.dictionary.values[2] = 8;
  rig.pdos.process(1000);
  tpdo = rig.frames_on(0x181);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].data[2], 8);
}

TEST(Pdo, inhibit_time_holds_back_changes_and_sends_the_latest_value) {
  PdoRig rig;
  rig.tpdo[0].inhibit_time_100us = 100;  // 10 ms
  rig.pdos.enter_operational();
  rig.pdos.process(0);
  EXPECT_EQ(rig.frames_on(0x181).size(), 1u);
  std::vector<int> sent_at_ms;
  for (int ms = 1; ms <= 25; ++ms) {
    rig.dictionary.values[2] = ms;  // changes every ms
    rig.pdos.process(1000);
    for (const can::CanFrame& f : rig.frames_on(0x181)) {
      sent_at_ms.push_back(ms);
      EXPECT_EQ(f.data[2], ms);
    }
  }
  EXPECT_EQ(sent_at_ms, (std::vector<int>{10, 20}));
}

TEST(Pdo, event_timer_repeats_an_unchanged_tpdo) {
  PdoRig rig;
  rig.tpdo[0].event_timer_ms = 20;
  rig.pdos.enter_operational();
  rig.pdos.process(0);
  EXPECT_EQ(rig.frames_on(0x181).size(), 1u);
  std::vector<int> sent_at_ms;
  for (int ms = 1; ms <= 65; ++ms) {
    rig.pdos.process(1000);
    if (!rig.frames_on(0x181).empty()) sent_at_ms.push_back(ms);
  }
  EXPECT_EQ(sent_at_ms, (std::vector<int>{20, 40, 60}));
}

TEST(Pdo, tpdo_mapping_an_absent_object_is_inactive) {
  PdoRig rig;
  rig.tpdo_mapping[0].entries[1] = 0x6041'0010;
  rig.pdos.enter_operational();
  for (int i = 0; i < 10; ++i) rig.pdos.process(1000);
  EXPECT_TRUE(rig.frames_on(0x181).empty());
}

TEST(Pdo, mappings_are_resolved_once_and_again_after_a_change) {
  PdoRig rig;
  rig.pdos.enter_operational();
  // Every PDO used once: each mapping resolved.
  ASSERT_EQ(rig.pdos.on_frame(frame_of(0x201, {1, 0, 2, 0, 0, 0})), RpdoReception::kAccepted);
  ASSERT_EQ(rig.pdos.on_frame(frame_of(0x301, {1, 0})), RpdoReception::kAccepted);
  rig.pdos.on_sync();
  rig.pdos.on_sync();
  rig.pdos.process(0);
  EXPECT_EQ(rig.can.take().size(), 2u);  // TPDO 1 (entering operational) and TPDO 2 (second SYNC)
  const int finds = rig.dictionary.finds;
  EXPECT_GT(finds, 0);
  for (int i = 0; i < 10; ++i) {
    rig.pdos.on_frame(frame_of(0x201, {static_cast<uint8_t>(i), 0, 2, 0, 0, 0}));
    rig.pdos.on_frame(frame_of(0x301, {static_cast<uint8_t>(i), 0}));
    rig.pdos.on_sync();
    rig.pdos.process(1000);
  }
  EXPECT_EQ(rig.dictionary.finds, finds);  // every object reached through its kept reference
  EXPECT_EQ(rig.dictionary.values[0], 9);
  rig.rpdo_mapping[0].entries[1] = 0x2000'0010;  // a remap resolves that mapping again
  rig.rpdo_mapping[0].entries[0] = 0x2001'0020;
  rig.pdos.on_frame(frame_of(0x201, {7, 0, 0, 0, 0x10, 0}));
  EXPECT_GT(rig.dictionary.finds, finds);
  EXPECT_EQ(rig.dictionary.values[1], 7);
  EXPECT_EQ(rig.dictionary.values[0], 0x10);
}

TEST(Pdo, remapped_rpdo_writes_the_new_objects_with_the_new_length) {
  PdoRig rig;
  ASSERT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x34, 0x12, 0x05, 0, 0, 0})), RpdoReception::kAccepted);
  EXPECT_EQ(rig.dictionary.values[0], 0x1234);
  EXPECT_EQ(rig.dictionary.values[1], 5);
  rig.rpdo_mapping[0] = PdoMapping{1, {0x2001'0020}};
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x06, 0, 0, 0})), RpdoReception::kAccepted);
  EXPECT_EQ(rig.dictionary.values[1], 6);
  EXPECT_EQ(rig.dictionary.values[0], 0x1234);  // no longer mapped
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x07, 0, 0, 0, 0x99, 0x99})), RpdoReception::kTooLong);
  EXPECT_EQ(rig.dictionary.values[1], 7);
  EXPECT_EQ(rig.dictionary.values[0], 0x1234);
  // Mapped to a read-only object: inactive, frames ignored; mapped back: written again.
  rig.rpdo_mapping[0] = PdoMapping{1, {0x2002'0008}};
  const int writes = rig.dictionary.writes;
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0x08})), RpdoReception::kAccepted);
  EXPECT_EQ(rig.dictionary.writes, writes);
  rig.rpdo_mapping[0] = PdoMapping{2, {0x0006'0010, 0x2000'0010}};  // dummy U16, then 2000
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x201, {0xFF, 0xFF, 0x21, 0x43})), RpdoReception::kAccepted);
  EXPECT_EQ(rig.dictionary.values[0], 0x4321);
}

TEST(Pdo, synchronous_rpdo_remapped_before_the_sync_uses_the_new_mapping_or_drops_short_data) {
  PdoRig rig;
  rig.pdos.on_frame(frame_of(0x301, {0x11, 0x00}));
  rig.rpdo_mapping[1] = PdoMapping{1, {0x2001'0020}};  // 4 bytes: the 2 kept do not fill it
  rig.pdos.on_sync();
  EXPECT_EQ(rig.dictionary.writes, 0);
  rig.rpdo_mapping[1] = PdoMapping{1, {0x2002'0008}};  // inactive (read-only object): frames ignored
  EXPECT_EQ(rig.pdos.on_frame(frame_of(0x301, {0x22, 0x00})), RpdoReception::kAccepted);
  rig.pdos.on_sync();
  EXPECT_EQ(rig.dictionary.writes, 0);
  rig.rpdo_mapping[1] = PdoMapping{1, {0x2001'0020}};
  rig.pdos.on_frame(frame_of(0x301, {0x33, 0x00, 0x00, 0x00}));
  rig.pdos.on_sync();
  EXPECT_EQ(rig.dictionary.values[1], 0x33);
}

TEST(Pdo, remapped_tpdo_carries_the_new_object) {
  PdoRig rig;
  rig.dictionary.values[0] = 0xBEEF;
  rig.dictionary.values[1] = -2;
  rig.dictionary.values[2] = 7;
  rig.pdos.enter_operational();
  rig.pdos.process(0);
  auto tpdo = rig.frames_on(0x181);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].dlc, 3);
  rig.tpdo_mapping[0] = PdoMapping{2, {0x2001'0020, 0x2002'0008}};
  rig.pdos.process(1000);  // what the PDO carries changed: sent
  tpdo = rig.frames_on(0x181);
  ASSERT_EQ(tpdo.size(), 1u);
  ASSERT_EQ(tpdo[0].dlc, 5);
  const uint8_t expected[5] = {0xFE, 0xFF, 0xFF, 0xFF, 7};
  for (int i = 0; i < 5; ++i) EXPECT_EQ(tpdo[0].data[i], expected[i]) << i;
  rig.dictionary.values[0] = 1;  // no longer mapped: no change
  rig.pdos.process(1000);
  EXPECT_TRUE(rig.frames_on(0x181).empty());
  rig.dictionary.values[1] = 3;
  rig.pdos.process(1000);
  tpdo = rig.frames_on(0x181);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].data[0], 3);
  // The synchronous TPDO: remapped between two SYNCs, the next one carries the new object.
  rig.pdos.on_sync();
  rig.pdos.on_sync();
  tpdo = rig.frames_on(0x281);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].dlc, 3);
  rig.tpdo_mapping[1] = PdoMapping{1, {0x2002'0008}};
  rig.pdos.on_sync();
  rig.pdos.on_sync();
  tpdo = rig.frames_on(0x281);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].dlc, 1);
  EXPECT_EQ(tpdo[0].data[0], 7);
}

TEST(Pdo, tpdo_mapped_back_from_an_absent_object_goes_out_again) {
  PdoRig rig;
  rig.tpdo_mapping[0].entries[1] = 0x6041'0010;
  rig.pdos.enter_operational();
  for (int i = 0; i < 5; ++i) rig.pdos.process(1000);
  EXPECT_TRUE(rig.frames_on(0x181).empty());
  rig.tpdo_mapping[0].entries[1] = 0x2002'0008;
  rig.pdos.process(1000);
  EXPECT_EQ(rig.frames_on(0x181).size(), 1u);
}

TEST(Sync, producer_sends_every_period_only_when_enabled_and_active) {
  RecordingCanController can;
  canopen::SyncService sync(can);
  sync.set_cycle_period_us(5000);
  for (int i = 0; i < 20; ++i) EXPECT_FALSE(sync.process(1000, true));  // bit 30 not set
  sync.set_cob_id(0x4000'0080);
  int produced = 0;
  for (int i = 0; i < 20; ++i) produced += sync.process(1000, true) ? 1 : 0;
  EXPECT_EQ(produced, 4);
  for (int i = 0; i < 20; ++i) EXPECT_FALSE(sync.process(1000, false));
  const auto frames = can.take();
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].id, 0x80u);
  EXPECT_EQ(frames[0].dlc, 0);
  EXPECT_TRUE(sync.is_sync(frame_of(0x80, {})));
  EXPECT_TRUE(sync.is_sync(frame_of(0x80, {7})));  // with a counter
  EXPECT_FALSE(sync.is_sync(frame_of(0x80, {1, 2})));
  EXPECT_FALSE(sync.is_sync(frame_of(0x81, {})));
}

// --- The TMCM-3216 -------------------------------------------------------------------------------

std::vector<can::CanFrame> only(const std::vector<can::CanFrame>& frames, uint32_t id) {
  std::vector<can::CanFrame> out;
  for (const can::CanFrame& f : frames) {
    if (f.id == id) out.push_back(f);
  }
  return out;
}

std::vector<can::CanFrame> run_ms(Tmcm3216Rig& rig, int ms) {
  std::vector<can::CanFrame> out;
  rig.can.take();
  for (int i = 0; i < ms; ++i) {
    rig.device->process(1000);  // 1 ms of the services
    for (const can::CanFrame& f : rig.can.take()) out.push_back(f);
  }
  return out;
}

// python-canopen's PdoMap.save(): COB-ID with bit 31, type, inhibit, event timer, SYNC start
// value (sub 6, may abort), mapping count 0, entries, count, COB-ID without bit 31.
void configure_tpdo_like_python_canopen(Tmcm3216Rig& rig, uint16_t comm, uint32_t cob_id, uint8_t type,
                                        uint16_t inhibit, uint16_t event_ms, std::vector<uint32_t> entries) {
  const uint16_t map = static_cast<uint16_t>(comm + 0x200);
  ASSERT_EQ(rig.download(comm, 1, cob_id | 0x8000'0000u), 0u);
  ASSERT_EQ(rig.download(comm, 2, type, 1), 0u);
  ASSERT_EQ(rig.download(comm, 3, inhibit, 2), 0u);
  ASSERT_EQ(rig.download(comm, 5, event_ms, 2), 0u);
  EXPECT_EQ(rig.download(comm, 6, 0, 1), 0x06090011u);  // no SYNC start value: python-canopen goes on
  ASSERT_EQ(rig.download(map, 0, 0, 1), 0u);
  for (size_t i = 0; i < entries.size(); ++i) {
    ASSERT_EQ(rig.download(map, static_cast<uint8_t>(i + 1), entries[i]), 0u);
  }
  ASSERT_EQ(rig.download(map, 0, static_cast<uint32_t>(entries.size()), 1), 0u);
  ASSERT_EQ(rig.download(comm, 1, cob_id), 0u);
}

// The manual's default PDOs (tables 41-47, axis 0's valid): starting the node sends the
// event-driven TPDO 1 (6041) and TPDO 2 (6041 + 6061) once; then, with no value changing, no
// event timer and no SYNC (TPDO 3/4), no PDO goes out.
TEST(Tmcm3216Pdo, default_tpdos_1_and_2_go_out_on_start_then_stay_silent) {
  Tmcm3216Rig rig;
  const auto at_start = rig.send(frame_of(0x000, {0x01, 0}));
  ASSERT_EQ(only(at_start, 0x181).size(), 1u);
  ASSERT_EQ(only(at_start, 0x281).size(), 1u);
  EXPECT_EQ(only(at_start, 0x181)[0].dlc, 2);  // 6041
  EXPECT_EQ(only(at_start, 0x281)[0].dlc, 3);  // 6041 + 6061
  const auto frames = run_ms(rig, 100);
  for (const can::CanFrame& f : frames) EXPECT_FALSE(f.id >= 0x180 && f.id < 0x580) << std::hex << f.id;
}

TEST(Tmcm3216Pdo, mapping_procedure_refusals) {
  Tmcm3216Rig rig;
  // Valid PDO: mapping frozen.
  EXPECT_EQ(rig.download(0x1A00, 0, 0, 1), 0x08000022u);
  ASSERT_EQ(rig.download(0x1800, 1, 0x8000'0181u), 0u);
  // Entries only while sub 0 is 0.
  EXPECT_EQ(rig.download(0x1A00, 1, 0x0005'0008), 0x08000022u);
  ASSERT_EQ(rig.download(0x1A00, 0, 0, 1), 0u);
  EXPECT_EQ(rig.download(0x1A00, 1, 0x1000'0020), 0x06040041u);  // 1000 is not mappable
  EXPECT_EQ(rig.download(0x1A00, 1, 0x1234'0010), 0x06040041u);  // absent
  EXPECT_EQ(rig.download(0x1A00, 1, 0x0006'0008), 0x06040041u);  // dummy U16 with 8 bits
  ASSERT_EQ(rig.download(0x1A00, 1, 0x0007'0020), 0u);
  ASSERT_EQ(rig.download(0x1A00, 2, 0x0007'0020), 0u);
  ASSERT_EQ(rig.download(0x1A00, 3, 0x0005'0008), 0u);
  EXPECT_EQ(rig.download(0x1A00, 0, 3, 1), 0x06040042u);  // 72 bits
  EXPECT_EQ(rig.download(0x1A00, 0, 4, 1), 0x06090031u);  // three entries at most
  ASSERT_EQ(rig.download(0x1A00, 0, 2, 1), 0u);
  EXPECT_EQ(rig.read_u32(0x1A00, 0) & 0xFF, 2u);
  // Transmission types 252/253 (RTR) and 0 are refused.
  EXPECT_EQ(rig.download(0x1800, 2, 253, 1), 0x06090030u);
  EXPECT_EQ(rig.download(0x1800, 2, 252, 1), 0x06090030u);
  EXPECT_EQ(rig.download(0x1800, 2, 0, 1), 0x06090030u);
}

TEST(Tmcm3216Pdo, event_timer_and_inhibit_time_after_python_canopen_reconfiguration) {
  Tmcm3216Rig rig;
  // TPDO 1: two dummy bytes, event driven, event timer 10 ms, inhibit 25 ms.
  configure_tpdo_like_python_canopen(rig, 0x1800, 0x181, 0xFF, 250, 10, {0x0005'0008, 0x0005'0008});
  // Entering operational: TPDO 1 at once.
  const auto at_start = only(rig.send(frame_of(0x000, {0x01, 1})), 0x181);
  ASSERT_EQ(at_start.size(), 1u);
  EXPECT_EQ(at_start[0].dlc, 2);
  EXPECT_EQ(at_start[0].data[0], 0);
  std::vector<int> sent_at_ms;
  for (int ms = 1; ms <= 80; ++ms) {
    rig.device->process(1000);  // 1 ms of the services
    if (!only(rig.can.take(), 0x181).empty()) sent_at_ms.push_back(ms);
  }
  EXPECT_EQ(sent_at_ms, (std::vector<int>{25, 50, 75}));  // event timer 10 ms, held back by 25 ms
  // Pre-operational: no PDOs.
  rig.nmt(0x80, 1);
  EXPECT_TRUE(only(run_ms(rig, 50), 0x181).empty());
}

TEST(Tmcm3216Pdo, synchronous_tpdo_counts_syncs_from_entering_operational) {
  Tmcm3216Rig rig;
  configure_tpdo_like_python_canopen(rig, 0x1801, 0x281, 3, 0, 0, {0x0007'0020});
  rig.nmt(0x01, 1);
  std::vector<int> sent_at_sync;
  for (int sync = 1; sync <= 10; ++sync) {
    const auto frames = rig.send(frame_of(0x080, {}));
    if (!only(frames, 0x281).empty()) sent_at_sync.push_back(sync);
  }
  EXPECT_EQ(sent_at_sync, (std::vector<int>{3, 6, 9}));
  // In pre-operational a SYNC does nothing.
  rig.nmt(0x80, 1);
  for (int sync = 0; sync < 6; ++sync) EXPECT_TRUE(only(rig.send(frame_of(0x080, {})), 0x281).empty());
}

TEST(Tmcm3216Pdo, pdos_of_axis_1_use_their_own_parameters) {
  Tmcm3216Rig rig;
  configure_tpdo_like_python_canopen(rig, 0x1841, 0x2C1, 1, 0, 0, {0x0006'0010});
  rig.nmt(0x01, 1);
  const auto frames = rig.send(frame_of(0x080, {}));
  const auto tpdo = only(frames, 0x2C1);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(tpdo[0].dlc, 2);
}

// The same for an RPDO (sub 1 and 2 only).
void configure_rpdo_like_python_canopen(Tmcm3216Rig& rig, uint16_t comm, uint32_t cob_id, uint8_t type,
                                        std::vector<uint32_t> entries) {
  const uint16_t map = static_cast<uint16_t>(comm + 0x200);
  ASSERT_EQ(rig.download(comm, 1, cob_id | 0x8000'0000u), 0u);
  ASSERT_EQ(rig.download(comm, 2, type, 1), 0u);
  ASSERT_EQ(rig.download(map, 0, 0, 1), 0u);
  for (size_t i = 0; i < entries.size(); ++i) {
    ASSERT_EQ(rig.download(map, static_cast<uint8_t>(i + 1), entries[i]), 0u);
  }
  ASSERT_EQ(rig.download(map, 0, static_cast<uint32_t>(entries.size()), 1), 0u);
  ASSERT_EQ(rig.download(comm, 1, cob_id), 0u);
}

TEST(Tmcm3216Pdo, remapped_pdos_of_axes_1_and_2_carry_the_new_objects) {
  Tmcm3216Rig rig;
  // RPDO 1 of axis 1 (1440): 6881 profile velocity of axis 1. TPDO 1 of axis 2 (1880),
  // synchronous: 7081 profile velocity of axis 2.
  configure_rpdo_like_python_canopen(rig, 0x1440, 0x215, 0xFF, {0x6881'0020});
  configure_tpdo_like_python_canopen(rig, 0x1880, 0x1A5, 1, 0, 0, {0x7081'0020});
  ASSERT_EQ(rig.download(0x7081, 0, 1111), 0u);
  ASSERT_EQ(rig.download(0x7083, 0, 2222), 0u);
  rig.nmt(0x01, 1);
  rig.send(frame_of(0x215, {0x39, 0x30, 0, 0}));  // 12345
  EXPECT_EQ(rig.read_u32(0x6881, 0), 12345u);
  auto tpdo = only(rig.send(frame_of(0x080, {})), 0x1A5);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(le32(tpdo[0], 0), 1111u);
  // Remapped while operational (each PDO not valid meanwhile), each to the profile acceleration
  // of its axis (6883, 7083): no NMT transition resets the PDO service in between.
  configure_rpdo_like_python_canopen(rig, 0x1440, 0x215, 0xFF, {0x6883'0020});
  configure_tpdo_like_python_canopen(rig, 0x1880, 0x1A5, 1, 0, 0, {0x7083'0020});
  ASSERT_EQ(rig.device->nmt_state(), canopen::NmtState::kOperational);
  rig.send(frame_of(0x215, {0x31, 0xD4, 0, 0}));  // 54321
  EXPECT_EQ(rig.read_u32(0x6883, 0), 54321u);
  EXPECT_EQ(rig.read_u32(0x6881, 0), 12345u);  // no longer mapped
  tpdo = only(rig.send(frame_of(0x080, {})), 0x1A5);
  ASSERT_EQ(tpdo.size(), 1u);
  EXPECT_EQ(le32(tpdo[0], 0), 2222u);
  // Restore defaults (1011 sub 1) and a reset: the default mappings and COB-IDs again (the PDOs
  // of axes 1 and 2 not valid).
  ASSERT_EQ(rig.download(0x1011, 1, 0x64616F6C), 0u);
  rig.nmt(0x81, 1);
  EXPECT_EQ(rig.read_u32(0x1A80, 1), 0x7041'0010u);
  EXPECT_EQ(rig.read_u32(0x1640, 1), 0x6840'0010u);
  rig.nmt(0x01, 1);
  const uint32_t acceleration = rig.read_u32(0x6883, 0);
  rig.send(frame_of(0x215, {0x01, 0x00, 0, 0}));
  EXPECT_EQ(rig.read_u32(0x6883, 0), acceleration);
  EXPECT_TRUE(only(rig.send(frame_of(0x080, {})), 0x1A5).empty());
}

TEST(Tmcm3216Pdo, rpdo_length_errors_send_emcy_8210_and_8220_and_0000_when_cleared) {
  Tmcm3216Rig rig;
  // RPDO 1: COB-ID 0x201, dummy U16 + dummy U8 = 3 bytes.
  ASSERT_EQ(rig.download(0x1400, 1, 0x8000'0201u), 0u);
  ASSERT_EQ(rig.download(0x1600, 0, 0, 1), 0u);
  ASSERT_EQ(rig.download(0x1600, 1, 0x0006'0010), 0u);
  ASSERT_EQ(rig.download(0x1600, 2, 0x0005'0008), 0u);
  ASSERT_EQ(rig.download(0x1600, 0, 2, 1), 0u);
  ASSERT_EQ(rig.download(0x1400, 1, 0x201), 0u);
  rig.nmt(0x01, 1);
  auto emcy = only(rig.send(frame_of(0x201, {1, 2})), 0x81);
  ASSERT_EQ(emcy.size(), 1u);
  const uint8_t short_frame[8] = {0x10, 0x82, 0x11, 0x00, 0xFF, 0, 0, 0};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(emcy[0].data[i], short_frame[i]) << i;
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0x11u);
  EXPECT_TRUE(only(rig.send(frame_of(0x201, {1, 2})), 0x81).empty());  // still the same error
  emcy = only(rig.send(frame_of(0x201, {1, 2, 3})), 0x81);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].data[0], 0x00);
  EXPECT_EQ(emcy[0].data[1], 0x00);
  EXPECT_EQ(emcy[0].data[2], 0x00);  // 1001 clear again
  emcy = only(rig.send(frame_of(0x201, {1, 2, 3, 4})), 0x81);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].data[0], 0x20);
  EXPECT_EQ(emcy[0].data[1], 0x82);
  // Not operational: RPDOs are not processed.
  rig.nmt(0x80, 1);
  EXPECT_TRUE(only(rig.send(frame_of(0x201, {1})), 0x81).empty());
}

TEST(Tmcm3216Pdo, receive_queue_overrun_sends_emcy_8110_then_0000) {
  Tmcm3216Rig rig;
  rig.can.take();
  for (size_t i = 0; i < Tmcm3216::kReceiveQueueLength + 3; ++i) rig.device->receive(frame_of(0x123, {1}));
  rig.device->process(0);
  auto emcy = only(rig.can.take(), 0x81);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].data[0], 0x10);
  EXPECT_EQ(emcy[0].data[1], 0x81);
  EXPECT_EQ(emcy[0].data[2], 0x11);
  EXPECT_EQ(rig.device->communication_errors(), Tmcm3216::kCommErrorCanOverrun);
  rig.device->process(1000);  // 1 ms of the services  // a tick without losses
  emcy = only(rig.can.take(), 0x81);
  ASSERT_EQ(emcy.size(), 1u);
  EXPECT_EQ(emcy[0].data[0], 0x00);
  EXPECT_EQ(emcy[0].data[2], 0x00);
  EXPECT_EQ(rig.device->communication_errors(), 0);
}

TEST(Tmcm3216Sync, sync_cob_id_change_moves_the_consumer) {
  Tmcm3216Rig rig;
  configure_tpdo_like_python_canopen(rig, 0x1800, 0x181, 1, 0, 0, {0x0005'0008});
  ASSERT_EQ(rig.download(0x1005, 0, 0x90), 0u);
  rig.nmt(0x01, 1);
  EXPECT_TRUE(only(rig.send(frame_of(0x080, {})), 0x181).empty());
  EXPECT_EQ(only(rig.send(frame_of(0x090, {})), 0x181).size(), 1u);
}

TEST(Tmcm3216Sync, producer_with_1005_bit_30_and_1006_drives_its_own_synchronous_tpdos) {
  Tmcm3216Rig rig;
  configure_tpdo_like_python_canopen(rig, 0x1800, 0x181, 2, 0, 0, {0x0005'0008});
  ASSERT_EQ(rig.download(0x1006, 0, 10000), 0u);  // 10 ms
  ASSERT_EQ(rig.download(0x1005, 0, 0x4000'0080), 0u);
  // Pre-operational: SYNCs, no PDOs.
  auto frames = run_ms(rig, 30);
  EXPECT_EQ(only(frames, 0x080).size(), 3u);
  EXPECT_TRUE(only(frames, 0x181).empty());
  rig.nmt(0x01, 1);
  frames = run_ms(rig, 100);
  EXPECT_EQ(only(frames, 0x080).size(), 10u);
  EXPECT_EQ(only(frames, 0x181).size(), 5u);  // every second SYNC
  EXPECT_EQ(rig.read_u32(0x1005, 0), 0x4000'0080u);
  // Stopped: no SYNC.
  rig.nmt(0x02, 1);
  EXPECT_TRUE(only(run_ms(rig, 50), 0x080).empty());
}

TEST(Tmcm3216Sync, sync_and_pdo_parameters_survive_store_and_power_cycle) {
  Tmcm3216Rig rig;
  configure_tpdo_like_python_canopen(rig, 0x1802, 0x381, 5, 0, 0, {0x0007'0020});
  ASSERT_EQ(rig.download(0x1006, 0, 2000), 0u);
  ASSERT_EQ(rig.download(0x1010, 1, 0x65766173), 0u);
  rig.power_cycle();
  EXPECT_EQ(rig.read_u32(0x1802, 1), 0x381u);
  EXPECT_EQ(rig.read_u32(0x1802, 2) & 0xFF, 5u);
  EXPECT_EQ(rig.read_u32(0x1A02, 0) & 0xFF, 1u);
  EXPECT_EQ(rig.read_u32(0x1A02, 1), 0x0007'0020u);
  EXPECT_EQ(rig.read_u32(0x1006, 0), 2000u);
}

}  // namespace
}  // namespace motwin::testing
