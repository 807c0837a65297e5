// The TMCM-3216 communication area (manual chapter 3) and its storage: defaults of tables 7-47,
// per-axis PDO objects, node ID handling, store/restore with signatures through the NVM.
#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "core/canopen/storage.h"
#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using modules::tmcm3216::Tmcm3216Config;

TEST(Tmcm3216Objects, table_has_no_duplicate_entries_and_sane_ranges) {
  std::set<std::pair<uint16_t, uint8_t>> seen;
  for (const Tmcm3216::Row& row : Tmcm3216::object_table()) {
    EXPECT_TRUE(seen.insert({row.info.index, row.info.sub}).second)
        << std::hex << row.info.index << " sub " << int(row.info.sub);
    if (canopen::is_numeric(row.info.type)) {
      EXPECT_LE(row.info.min, row.info.max) << std::hex << row.info.index;
      EXPECT_GE(row.info.default_value, row.info.min) << std::hex << row.info.index;
      EXPECT_LE(row.info.default_value, row.info.max) << std::hex << row.info.index;
    }
    if (row.info.storage == canopen::StorageGroup::kAxis) {
      EXPECT_NE(row.info.axis_stride, 0);
    }
  }
}

TEST(Tmcm3216Objects, communication_area_defaults_of_chapter_3) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);
  EXPECT_EQ(rig.read_u32(0x1001, 0) & 0xFF, 0u);
  EXPECT_EQ(rig.read_u32(0x1005, 0), 0x80u);
  EXPECT_EQ(rig.read_u32(0x1014, 0), 0x81u);
  EXPECT_EQ(rig.read_u32(0x1015, 0) & 0xFFFF, 0u);
  EXPECT_EQ(rig.read_u32(0x1016, 0) & 0xFF, 1u);
  EXPECT_EQ(rig.read_u32(0x1016, 1), 0u);
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 0u);
  EXPECT_EQ(rig.read_u32(0x1029, 0) & 0xFF, 2u);
  EXPECT_EQ(rig.read_u32(0x1029, 1) & 0xFF, 0u);
  EXPECT_EQ(rig.read_u32(0x1029, 2) & 0xFF, 1u);
  EXPECT_EQ(rig.read_u32(0x1010, 0) & 0xFF, 6u);
  const uint32_t store_caps[] = {1, 1, 0, 1, 1, 1};
  for (uint8_t sub = 1; sub <= 6; ++sub) {
    EXPECT_EQ(rig.read_u32(0x1010, sub), store_caps[sub - 1]) << int(sub);
    EXPECT_EQ(rig.read_u32(0x1011, sub), store_caps[sub - 1]) << int(sub);
  }
  EXPECT_EQ(rig.read_u32(0x2704, 0) & 0xFFFF, 1000u);
  EXPECT_EQ(rig.read_u32(0x2705, 0) & 0xFF, 1u);
  EXPECT_EQ(rig.read_u32(0x2707, 0) & 0xFFFF, 1000u);
  EXPECT_EQ(rig.read_u32(0x2708, 0) & 0xFF, 1u);
}

TEST(Tmcm3216Objects, pdo_defaults_of_tables_41_to_47) {
  Tmcm3216Rig rig;
  const uint32_t rpdo_cob[] = {0x201, 0x301, 0x401, 0x501};
  const uint32_t rpdo_type[] = {0xFF, 0xFF, 0xFF, 0xFE};
  const uint32_t rpdo_count[] = {1, 2, 2, 2};
  const uint32_t rpdo_map2[] = {0, 0x60600008, 0x607A0020, 0x60FF0020};
  const uint32_t tpdo_cob[] = {0x181, 0x281, 0x381, 0x481};
  const uint32_t tpdo_type[] = {0xFF, 0xFF, 0x01, 0x01};
  const uint32_t tpdo_map2[] = {0, 0x60610008, 0x60640020, 0x606C0020};
  for (uint16_t k = 0; k < 4; ++k) {
    EXPECT_EQ(rig.read_u32(0x1400 + k, 0) & 0xFF, 2u);
    EXPECT_EQ(rig.read_u32(0x1400 + k, 1), rpdo_cob[k]);
    EXPECT_EQ(rig.read_u32(0x1400 + k, 2) & 0xFF, rpdo_type[k]);
    EXPECT_EQ(rig.read_u32(0x1600 + k, 0) & 0xFF, rpdo_count[k]);
    EXPECT_EQ(rig.read_u32(0x1600 + k, 1), 0x60400010u);
    EXPECT_EQ(rig.read_u32(0x1600 + k, 2), rpdo_map2[k]);
    EXPECT_EQ(rig.read_u32(0x1600 + k, 3), 0u);
    EXPECT_EQ(rig.read_u32(0x1800 + k, 0) & 0xFF, 5u);
    EXPECT_EQ(rig.read_u32(0x1800 + k, 1), tpdo_cob[k]);
    EXPECT_EQ(rig.read_u32(0x1800 + k, 2) & 0xFF, tpdo_type[k]);
    EXPECT_EQ(rig.read_u32(0x1800 + k, 3) & 0xFFFF, 0u);
    EXPECT_EQ(rig.read_u32(0x1800 + k, 4) & 0xFF, 0u);
    EXPECT_EQ(rig.read_u32(0x1800 + k, 5) & 0xFFFF, 0u);
    EXPECT_EQ(rig.read_u32(0x1A00 + k, 0) & 0xFF, rpdo_count[k]);
    EXPECT_EQ(rig.read_u32(0x1A00 + k, 1), 0x60410010u);
    EXPECT_EQ(rig.read_u32(0x1A00 + k, 2), tpdo_map2[k]);
  }
}

TEST(Tmcm3216Objects, pdos_of_axes_1_and_2_start_disabled_and_map_their_own_axis) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.read_u32(0x1440, 1), 0x80000201u);
  EXPECT_EQ(rig.read_u32(0x1880, 1), 0x80000181u);
  EXPECT_EQ(rig.read_u32(0x1641, 2), 0x68600008u);
  EXPECT_EQ(rig.read_u32(0x1A82, 2), 0x70640020u);
  EXPECT_EQ(rig.read_u32(0x1A82, 3), 0u);
}

TEST(Tmcm3216Objects, node_id_from_switches_moves_the_node_id_relative_defaults) {
  Tmcm3216Config config;
  config.node_id_switches = 5;
  Tmcm3216Rig rig(config);
  EXPECT_EQ(rig.node(), 5);
  const std::vector<can::CanFrame> boot = rig.can.take();
  ASSERT_EQ(boot.size(), 1u);
  EXPECT_EQ(boot[0].id, 0x705u);
  EXPECT_EQ(rig.read_u32(0x1014, 0), 0x85u);
  EXPECT_EQ(rig.read_u32(0x1800, 1), 0x185u);
  EXPECT_EQ(rig.read_u32(0x1403, 1), 0x505u);
  EXPECT_EQ(rig.read_u32(0x2708, 0) & 0xFF, 5u);
  EXPECT_EQ(rig.read_u32(0x2705, 0) & 0xFF, 1u);  // the stored setting
}

TEST(Tmcm3216Objects, pdo_reconfiguration_in_python_canopen_order) {
  Tmcm3216Rig rig;
  // Invalidate, set type / inhibit / event timer, clear mapping, (entries), count, revalidate.
  EXPECT_EQ(rig.download(0x1800, 1, 0xC0000181), 0u);
  EXPECT_EQ(rig.download(0x1800, 2, 1, 1), 0u);
  EXPECT_EQ(rig.download(0x1800, 3, 100, 2), 0u);
  EXPECT_EQ(rig.download(0x1800, 5, 250, 2), 0u);
  EXPECT_EQ(rig.download(0x1A00, 0, 0, 1), 0u);
  EXPECT_EQ(rig.download(0x1A00, 1, 0x10000010), 0x06040041u);  // no mappable object yet (CiA-402 issue)
  EXPECT_EQ(rig.download(0x1A00, 1, 0), 0u);
  EXPECT_EQ(rig.download(0x1800, 1, 0x40000181), 0u);
  EXPECT_EQ(rig.read_u32(0x1800, 1), 0x40000181u);
  EXPECT_EQ(rig.read_u32(0x1800, 3) & 0xFFFF, 100u);
  // Valid again: no mapping change, no inhibit time change, no new COB-ID.
  EXPECT_EQ(rig.download(0x1A00, 0, 0, 1), 0x08000022u);
  EXPECT_EQ(rig.download(0x1800, 3, 10, 2), 0x06090030u);
  EXPECT_EQ(rig.download(0x1800, 1, 0x40000182), 0x06090030u);
  EXPECT_EQ(rig.download(0x1800, 5, 100, 2), 0u);  // event timer: any time
}

TEST(Tmcm3216Objects, rpdo_mapping_accepts_dummy_entries_and_checks_length) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.download(0x1400, 1, 0x80000201), 0u);
  EXPECT_EQ(rig.download(0x1600, 0, 0, 1), 0u);
  EXPECT_EQ(rig.download(0x1600, 1, 0x00070020), 0u);  // UNSIGNED32 dummy
  EXPECT_EQ(rig.download(0x1600, 2, 0x00070020), 0u);
  EXPECT_EQ(rig.download(0x1600, 3, 0x00050008), 0u);
  EXPECT_EQ(rig.download(0x1600, 0, 3, 1), 0x06040042u);  // 72 bits
  EXPECT_EQ(rig.download(0x1600, 0, 2, 1), 0u);
  EXPECT_EQ(rig.download(0x1600, 1, 0x00060010), 0x08000022u);  // sub 0 != 0
  EXPECT_EQ(rig.download(0x1600, 0, 4, 1), 0x06090031u);
  EXPECT_EQ(rig.download(0x1600, 0, 0, 1), 0u);
  EXPECT_EQ(rig.download(0x1600, 1, 0x00070010), 0x06040041u);  // wrong length for the dummy
  EXPECT_EQ(rig.download(0x1A01, 1, 0x00070020), 0x08000022u);   // TPDO 2 still valid
  EXPECT_EQ(rig.download(0x1400, 1, 0x00000201), 0u);  // valid again with two dummies mapped
}

TEST(Tmcm3216Objects, pdo_cob_ids_refuse_restricted_and_extended_ids) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.download(0x1400, 1, 0x80000201), 0u);
  EXPECT_EQ(rig.download(0x1400, 1, 0x00000601), 0x06090030u);  // SDO request ID
  EXPECT_EQ(rig.download(0x1400, 1, 0x00000701), 0x06090030u);  // heartbeat
  EXPECT_EQ(rig.download(0x1400, 1, 0x00000050), 0x06090030u);
  EXPECT_EQ(rig.download(0x1400, 1, 0x20000201), 0x06090030u);  // 29-bit
  EXPECT_EQ(rig.download(0x1400, 1, 0x00000222), 0u);
  EXPECT_EQ(rig.read_u32(0x1400, 1), 0x222u);
}

TEST(Tmcm3216Objects, store_all_survives_power_cycle) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1017, 0, 250, 2), 0u);
  ASSERT_EQ(rig.download(0x1029, 1, 2, 1), 0u);
  ASSERT_EQ(rig.download(0x1800, 5, 20, 2), 0u);
  ASSERT_EQ(rig.download(0x1880, 1, 0x80000190), 0u);
  ASSERT_EQ(rig.download(0x1010, 1, 0x65766173), 0u);
  EXPECT_EQ(rig.nvm->write_count(), 1u);
  ASSERT_EQ(rig.download(0x1017, 0, 999, 2), 0u);  // not stored
  rig.power_cycle();
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 250u);
  EXPECT_EQ(rig.read_u32(0x1029, 1) & 0xFF, 2u);
  EXPECT_EQ(rig.read_u32(0x1800, 5) & 0xFFFF, 20u);
  EXPECT_EQ(rig.read_u32(0x1880, 1), 0x80000190u);
  EXPECT_EQ(rig.read_u32(0x1800, 1), 0x181u);
}

TEST(Tmcm3216Objects, unsaved_values_are_lost_at_reset_node) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1015, 0, 30, 2), 0u);
  rig.nmt(0x81, 1);
  EXPECT_EQ(rig.read_u32(0x1015, 0) & 0xFFFF, 0u);
}

TEST(Tmcm3216Objects, restore_defaults_take_effect_after_reset) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1017, 0, 250, 2), 0u);
  ASSERT_EQ(rig.download(0x2705, 0, 7, 1), 0u);
  ASSERT_EQ(rig.download(0x1010, 1, 0x65766173), 0u);
  ASSERT_EQ(rig.download(0x1011, 1, 0x64616F6C), 0u);
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 250u) << "restored defaults apply after the next reset";
  rig.power_cycle();
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 0u);
  EXPECT_EQ(rig.node(), 7) << "restore all keeps the node ID (manual: restoring it has no function)";
}

TEST(Tmcm3216Objects, node_id_change_through_2705_and_2706_applies_after_reset) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x2705, 0, 42, 1), 0u);
  ASSERT_EQ(rig.download(0x2704, 0, 500, 2), 0u);
  EXPECT_EQ(rig.read_u32(0x2708, 0) & 0xFF, 1u);
  ASSERT_EQ(rig.download(0x2706, 1, 0x65766173), 0u);
  const std::vector<can::CanFrame> out = rig.send(frame_of(0x000, {0x82, 0x01}));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x700u + 42);
  EXPECT_EQ(rig.node(), 42);
  EXPECT_EQ(rig.read_u32(0x2708, 0) & 0xFF, 42u);
  EXPECT_EQ(rig.read_u32(0x2707, 0) & 0xFFFF, 500u);
  EXPECT_EQ(rig.read_u32(0x1014, 0), 0x80u + 42);
}

TEST(Tmcm3216Objects, node_settings_are_saved_by_1010_sub_2_only_with_its_group) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x2705, 0, 9, 1), 0u);
  ASSERT_EQ(rig.download(0x1017, 0, 100, 2), 0u);
  ASSERT_EQ(rig.download(0x1010, 2, 0x65766173), 0u);
  rig.power_cycle();
  EXPECT_EQ(rig.node(), 9);
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 0u);
}

TEST(Tmcm3216Objects, node_id_relative_cob_ids_follow_a_new_node_id) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1010, 1, 0x65766173), 0u);  // defaults stored as "default"
  ASSERT_EQ(rig.download(0x2705, 0, 3, 1), 0u);
  ASSERT_EQ(rig.download(0x2706, 1, 0x65766173), 0u);
  rig.power_cycle();
  EXPECT_EQ(rig.read_u32(0x1800, 1), 0x183u);
  EXPECT_EQ(rig.read_u32(0x1014, 0), 0x83u);
}

TEST(Tmcm3216Objects, failed_nvm_write_aborts_06060000_and_keeps_the_image) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x1017, 0, 250, 2), 0u);
  rig.nvm->set_fail_writes(true);
  EXPECT_EQ(rig.download(0x1010, 1, 0x65766173), 0x06060000u);
  rig.nvm->set_fail_writes(false);
  rig.power_cycle();
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 0u);
}

TEST(Tmcm3216Objects, damaged_image_gives_defaults) {
  Tmcm3216Rig rig({}, /*format=*/false);  // all zero bytes: no magic
  EXPECT_EQ(rig.node(), 1);
  EXPECT_EQ(rig.read_u32(0x1014, 0), 0x81u);
  ASSERT_EQ(rig.download(0x1017, 0, 100, 2), 0u);
  ASSERT_EQ(rig.download(0x1010, 1, 0x65766173), 0u);
  rig.power_cycle();
  EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, 100u);
}

TEST(Tmcm3216Objects, unconfigured_node_id_255_stays_silent) {
  Tmcm3216Rig rig;
  ASSERT_EQ(rig.download(0x2705, 0, 255, 1), 0u);
  ASSERT_EQ(rig.download(0x2706, 1, 0x65766173), 0u);
  rig.can.take();
  rig.power_cycle();
  EXPECT_FALSE(rig.device->configured());
  EXPECT_TRUE(rig.can.take().empty());
  EXPECT_TRUE(rig.send(frame_of(0x600 + 255, {0x40, 0, 0x10, 0, 0, 0, 0, 0})).empty());
  Tmcm3216Config switches;
  switches.node_id_switches = 4;
  rig.power_cycle(switches);
  EXPECT_EQ(rig.node(), 4);
}

TEST(Tmcm3216Objects, serial_number_comes_from_the_board) {
  Tmcm3216Config config;
  config.serial_number = 0xC0FFEE;
  Tmcm3216Rig rig(config);
  EXPECT_EQ(rig.read_u32(0x1018, 4), 0xC0FFEEu);
}

TEST(Tmcm3216Objects, receive_queue_overflow_drops_frames_and_keeps_working) {
  Tmcm3216Rig rig;
  for (size_t i = 0; i < Tmcm3216::kReceiveQueueLength + 5; ++i) rig.device->receive(frame_of(0x123, {1, 2}));
  EXPECT_EQ(rig.device->dropped_frames(), 5u);
  rig.device->process(0);
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);
}

}  // namespace
}  // namespace motwin::testing
