// NMT resets of the TMCM-3216 and the conformance cases of issue 17: reset node returns every
// application object (2000h..9FFFh, every axis) to its power-on value or the stored one, reset
// communication leaves them alone; the SYNC COB-ID 1005 refuses restricted identifiers and a
// new identifier while SYNC is produced; 2703 sub 1 refuses bits that name no output; the
// restart time before the boot-up, during which the node hears and sends nothing.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "support/canopen_rig.h"

namespace motwin::testing {
namespace {

using modules::tmcm3216::Tmcm3216Config;

constexpr uint32_t kAbortInvalidValue = 0x06090030;

// One writable numeric entry of the application area for one axis.
struct Entry {
  canopen::ObjectRef ref;
  int64_t power_on = 0;
};

bool application_area(uint16_t index) { return index >= 0x2000 && index <= 0x9FFF; }

// Signature-taking actions: a read gives what can be stored, not what was written.
bool action(uint16_t index) { return index == 0x1010 || index == 0x1011 || index == 0x2706; }

std::string name_of(const canopen::ObjectRef& ref) {
  std::ostringstream out;
  out << std::hex << ref.index << " sub " << std::dec << int(ref.info->sub) << " (" << ref.info->name << ")";
  return out.str();
}

int64_t value_of(Tmcm3216& device, const canopen::ObjectRef& ref) {
  uint8_t bytes[8] = {};
  size_t length = 0;
  EXPECT_EQ(device.dictionary().read(ref, bytes, sizeof(bytes), length), canopen::SdoAbort::kNone) << name_of(ref);
  return canopen::decode_value(ref.info->type, bytes);
}

canopen::SdoAbort write_value(Tmcm3216& device, const canopen::ObjectRef& ref, int64_t value) {
  uint8_t bytes[8] = {};
  canopen::encode_value(ref.info->type, value, bytes);
  return device.dictionary().write(ref, bytes, canopen::type_size(ref.info->type));
}

// Every writable numeric entry of the application area (or of the communication area) on every
// axis that can take more than one value, with what it reads right after power-up.
std::vector<Entry> writable_entries(Tmcm3216& device, bool application) {
  std::vector<Entry> entries;
  auto& dictionary = device.dictionary();
  for (size_t row = 0; row < dictionary.rows().size(); ++row) {
    const canopen::EntryInfo& info = dictionary.rows()[row].info;
    if (!canopen::is_numeric(info.type) || !canopen::writable(info.access) || action(info.index)) continue;
    if (info.min == info.max) continue;  // one value only (605B..605E): nothing to change
    if (application_area(info.index) != application) continue;
    for (uint8_t axis = 0; axis < dictionary.axes_of(info); ++axis) {
      Entry entry;
      entry.ref = dictionary.ref(row, axis);
      entry.power_on = value_of(device, entry.ref);
      entries.push_back(entry);
    }
  }
  return entries;
}

// Writes a valid value other than those in `avoid`; the value written, or nullopt when no
// candidate is accepted.
std::optional<int64_t> write_other_value(Tmcm3216& device, const canopen::ObjectRef& ref,
                                         const std::vector<int64_t>& avoid) {
  const canopen::EntryInfo& info = *ref.info;
  const int64_t base = avoid.front();
  const int64_t candidates[] = {base + 1, base - 1, base + 2, info.max, info.min, 1, 2, 3, 6, 0x10000, 0x20000, -2};
  for (const int64_t candidate : candidates) {
    if (candidate < info.min || candidate > info.max) continue;
    bool avoided = false;
    for (const int64_t a : avoid) avoided = avoided || a == candidate;
    if (avoided) continue;
    if (write_value(device, ref, candidate) != canopen::SdoAbort::kNone) continue;
    if (value_of(device, ref) == candidate) return candidate;
  }
  return std::nullopt;
}

TEST(Tmcm3216Reset, power_on_values_are_the_table_defaults) {
  Tmcm3216Rig rig;
  for (const Entry& entry : writable_entries(*rig.device, true)) {
    EXPECT_EQ(entry.power_on, rig.device->dictionary().default_value(*entry.ref.info, entry.ref.axis))
        << name_of(entry.ref);
  }
}

// The walk of issue 17: a valid non-default value into every writable application entry, NMT
// reset node, and every entry reads its power-on value again. Before the fix 6060, 607A, 60FF,
// 60B0, 60B1 of each axis, 2711, 2703 sub 1 and sub 2 kept what was written.
TEST(Tmcm3216Reset, reset_node_returns_every_application_object_to_its_power_on_value) {
  Tmcm3216Rig rig;
  std::vector<Entry> entries = writable_entries(*rig.device, true);
  ASSERT_GT(entries.size(), 200u);
  for (const Entry& entry : entries) {
    EXPECT_TRUE(write_other_value(*rig.device, entry.ref, {entry.power_on}).has_value())
        << "no valid value other than the power-on one for " << name_of(entry.ref);
  }
  size_t changed = 0;
  for (const Entry& entry : entries) changed += value_of(*rig.device, entry.ref) != entry.power_on ? 1 : 0;
  EXPECT_EQ(changed, entries.size()) << "entries that hold a written value before the reset";
  rig.nmt(0x81, 0);
  EXPECT_FALSE(rig.device->restarting());
  for (const Entry& entry : entries) {
    EXPECT_EQ(value_of(*rig.device, entry.ref), entry.power_on) << name_of(entry.ref) << " survived reset node";
  }
}

// With 1010 sub 1 ("save") in between: stored entries come back with the stored value, the
// others with their power-on value.
TEST(Tmcm3216Reset, reset_node_restores_stored_values_and_power_on_values_of_the_rest) {
  Tmcm3216Rig rig;
  std::vector<Entry> entries = writable_entries(*rig.device, true);
  std::vector<int64_t> saved(entries.size());
  for (size_t i = 0; i < entries.size(); ++i) {
    const std::optional<int64_t> value = write_other_value(*rig.device, entries[i].ref, {entries[i].power_on});
    ASSERT_TRUE(value.has_value()) << name_of(entries[i].ref);
    saved[i] = *value;
  }
  ASSERT_EQ(rig.download(0x1010, 1, Tmcm3216::kSaveSignature), 0u);
  for (size_t i = 0; i < entries.size(); ++i) {
    // Another value where one is accepted (the 2005/200B/200C rows need SWITCH ON DISABLED,
    // which holds: nothing enabled a drive).
    write_other_value(*rig.device, entries[i].ref, {entries[i].power_on, saved[i]});
  }
  rig.nmt(0x81, 0);
  size_t stored = 0;
  for (size_t i = 0; i < entries.size(); ++i) {
    const bool is_stored = entries[i].ref.info->storage != canopen::StorageGroup::kNone;
    stored += is_stored ? 1 : 0;
    EXPECT_EQ(value_of(*rig.device, entries[i].ref), is_stored ? saved[i] : entries[i].power_on)
        << name_of(entries[i].ref) << (is_stored ? " (stored)" : " (not stored)");
  }
  EXPECT_GT(stored, 150u);
}

// Reset communication touches 1000h..1FFFh only: the application objects keep their values
// (2705 too: the node ID in force comes from the NVM, as the manual's "write, store, reset").
TEST(Tmcm3216Reset, reset_communication_leaves_the_application_objects_alone) {
  Tmcm3216Rig rig;
  std::vector<Entry> entries = writable_entries(*rig.device, true);
  std::vector<int64_t> written(entries.size());
  for (size_t i = 0; i < entries.size(); ++i) {
    written[i] = write_other_value(*rig.device, entries[i].ref, {entries[i].power_on}).value_or(entries[i].power_on);
  }
  std::vector<Entry> communication = writable_entries(*rig.device, false);
  for (const Entry& entry : communication) {
    // A few communication entries refuse any other value in this state (mapping entries while
    // the PDO is valid): those are not part of this check.
    write_other_value(*rig.device, entry.ref, {entry.power_on});
  }
  rig.nmt(0x82, 0);
  for (size_t i = 0; i < entries.size(); ++i) {
    EXPECT_EQ(value_of(*rig.device, entries[i].ref), written[i]) << name_of(entries[i].ref) << " after reset communication";
  }
  for (const Entry& entry : communication) {
    EXPECT_EQ(value_of(*rig.device, entry.ref), entry.power_on) << name_of(entry.ref) << " after reset communication";
  }
  EXPECT_EQ(rig.device->node_id(), 1) << "2705 written but not stored";
}

// The conformance case as raw frames: 6060 = 1, NMT reset node, 6060 reads 0.
TEST(Tmcm3216Reset, conformance_case_mode_of_operation_after_reset_node) {
  Tmcm3216Rig rig;
  EXPECT_EQ(rig.sdo({0x2F, 0x60, 0x60, 0x00, 0x01, 0, 0, 0}).data[0], 0x60);
  EXPECT_EQ(rig.read_u32(0x6060, 0) & 0xFF, 1u);
  const std::vector<can::CanFrame> out = rig.send(frame_of(0x000, {0x81, 0x01}));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, 0x701u);  // boot-up
  EXPECT_EQ(rig.read_u32(0x6060, 0) & 0xFF, 0u);
}

// --- 1005 ----------------------------------------------------------------------------------------

uint32_t download_1005(Tmcm3216Rig& rig, uint32_t value) {
  const can::CanFrame response =
      rig.sdo({0x23, 0x05, 0x10, 0x00, static_cast<uint8_t>(value), static_cast<uint8_t>(value >> 8),
               static_cast<uint8_t>(value >> 16), static_cast<uint8_t>(value >> 24)});
  return Tmcm3216Rig::abort_of(response);
}

TEST(Tmcm3216Sync, cob_id_refuses_the_restricted_identifiers_of_cia_301) {
  Tmcm3216Rig rig;
  const uint32_t restricted[] = {0x000, 0x001, 0x07F, 0x101, 0x180, 0x581, 0x5FF, 0x601,
                                 0x67F, 0x6E0, 0x6FF, 0x701, 0x77F, 0x780, 0x7FF};
  for (const uint32_t id : restricted) {
    EXPECT_EQ(download_1005(rig, id), kAbortInvalidValue) << std::hex << id;
    EXPECT_EQ(download_1005(rig, 0x4000'0000 | id), kAbortInvalidValue) << std::hex << id << " with bit 30";
    EXPECT_EQ(rig.read_u32(0x1005, 0), 0x80u) << "unchanged after " << std::hex << id;
  }
  const uint32_t allowed[] = {0x080, 0x0FF, 0x100, 0x181, 0x580, 0x600, 0x680, 0x6DF, 0x700, 0x085};
  for (const uint32_t id : allowed) {
    EXPECT_EQ(download_1005(rig, id), 0u) << std::hex << id;
    EXPECT_EQ(rig.read_u32(0x1005, 0), id);
  }
}

TEST(Tmcm3216Sync, cob_id_is_fixed_while_the_node_produces_sync) {
  Tmcm3216Rig rig;
  EXPECT_EQ(download_1005(rig, 0x4000'0080), 0u);  // producer on, same identifier
  EXPECT_EQ(download_1005(rig, 0x4000'0081), kAbortInvalidValue);
  EXPECT_EQ(download_1005(rig, 0x0000'0081), kAbortInvalidValue) << "bit 30 is cleared first, alone";
  EXPECT_EQ(download_1005(rig, 0x4000'0080), 0u) << "the same value again";
  EXPECT_EQ(rig.read_u32(0x1005, 0), 0x4000'0080u);
  EXPECT_EQ(download_1005(rig, 0x0000'0080), 0u);  // producer off
  EXPECT_EQ(download_1005(rig, 0x0000'0081), 0u);
  EXPECT_EQ(download_1005(rig, 0x4000'0081), 0u);
  EXPECT_EQ(rig.read_u32(0x1005, 0), 0x4000'0081u);
}

// --- 2703 sub 1 (the canopen_sdo fuzz finding) ---------------------------------------------------

TEST(Tmcm3216Io, physical_outputs_refuse_bits_that_name_no_output_and_read_back_what_they_take) {
  Tmcm3216Rig rig;
  // The finding's download: "save" into 2703 sub 1 was acknowledged and read 0.
  EXPECT_EQ(Tmcm3216Rig::abort_of(rig.sdo({0x23, 0x03, 0x27, 0x01, 0x73, 0x61, 0x76, 0x65})), kAbortInvalidValue);
  EXPECT_EQ(rig.read_u32(0x2703, 1), 0u);
  EXPECT_EQ(rig.download(0x2703, 1, 0x000A0000), 0u);  // the mask is 0: no output switches
  EXPECT_EQ(rig.read_u32(0x2703, 1), 0x000A0000u);
  EXPECT_EQ(rig.device->general_io().output_levels(), 0u);
  EXPECT_EQ(rig.download(0x2703, 2, 0x00020000), 0u);
  EXPECT_EQ(rig.download(0x2703, 1, 0x000A0000), 0u);
  EXPECT_EQ(rig.device->general_io().output_levels(), 0x00020000u);
}

// --- Restart time ------------------------------------------------------------------------------

Tmcm3216Config with_boot_delays() {
  Tmcm3216Config config;
  config.boot_delay_us = Tmcm3216::kBootDelayUs;
  config.communication_boot_delay_us = Tmcm3216::kCommunicationBootDelayUs;
  return config;
}

bool has_bootup(const std::vector<can::CanFrame>& frames, uint8_t node) {
  for (const can::CanFrame& f : frames) {
    if (f.id == 0x700u + node && f.dlc == 1 && f.data[0] == 0) return true;
  }
  return false;
}

// Runs the services for `us` in 1 ms steps (the module's service tick); the frames sent.
std::vector<can::CanFrame> run_us(Tmcm3216Rig& rig, uint32_t us) {
  std::vector<can::CanFrame> out;
  for (uint32_t t = 0; t < us; t += 1000) {
    rig.device->process(1000);
    for (const can::CanFrame& f : rig.can.take()) out.push_back(f);
  }
  return out;
}

// While restarting, a request gets nothing: an SDO upload, an NMT command, an LSS inquiry.
void expect_deaf(Tmcm3216Rig& rig) {
  EXPECT_TRUE(rig.send(frame_of(0x601, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0})).empty());
  EXPECT_TRUE(rig.send(frame_of(0x000, {0x01, 0x01})).empty());
  EXPECT_TRUE(rig.send(frame_of(0x7E5, {0x5E, 0, 0, 0, 0, 0, 0, 0})).empty());
}

TEST(Tmcm3216Restart, power_up_boots_after_the_restart_time_and_is_deaf_before) {
  Tmcm3216Rig rig(with_boot_delays());
  EXPECT_TRUE(rig.device->restarting());
  EXPECT_EQ(rig.device->nmt_state(), canopen::NmtState::kInitializing);
  EXPECT_FALSE(has_bootup(rig.can.take(), 1));
  EXPECT_TRUE(run_us(rig, Tmcm3216::kBootDelayUs - 1000).empty());
  expect_deaf(rig);
  const std::vector<can::CanFrame> out = run_us(rig, 1000);
  ASSERT_EQ(out.size(), 1u) << "the boot-up alone: the requests of the restart were dropped";
  EXPECT_TRUE(has_bootup(out, 1));
  EXPECT_EQ(rig.device->nmt_state(), canopen::NmtState::kPreOperational);
  EXPECT_EQ(rig.read_u32(0x1000, 0), 0xFFFF0192u);
}

TEST(Tmcm3216Restart, reset_node_and_reset_communication_take_their_restart_times) {
  Tmcm3216Rig rig(with_boot_delays());
  run_us(rig, Tmcm3216::kBootDelayUs);
  EXPECT_EQ(rig.download(0x1017, 0, 100, 2), 0u);  // heartbeats: none while restarting
  rig.nmt(0x01, 1);
  EXPECT_EQ(rig.device->nmt_state(), canopen::NmtState::kOperational);
  struct Case {
    uint8_t command;
    uint32_t delay_us;
  };
  for (const Case c : {Case{0x81, Tmcm3216::kBootDelayUs}, Case{0x82, Tmcm3216::kCommunicationBootDelayUs}}) {
    EXPECT_TRUE(rig.send(frame_of(0x000, {c.command, 0x01})).empty()) << int(c.command);
    EXPECT_TRUE(rig.device->restarting());
    EXPECT_TRUE(run_us(rig, c.delay_us - 1000).empty()) << int(c.command);
    expect_deaf(rig);
    const std::vector<can::CanFrame> out = run_us(rig, 1000);
    ASSERT_EQ(out.size(), 1u) << int(c.command);
    EXPECT_TRUE(has_bootup(out, 1)) << int(c.command);
    EXPECT_EQ(rig.device->nmt_state(), canopen::NmtState::kPreOperational);
    rig.other.clear();
    EXPECT_EQ(rig.read_u32(0x1017, 0) & 0xFFFF, c.command == 0x81 ? 0u : 0u);  // not stored: default
    EXPECT_EQ(rig.download(0x1017, 0, 100, 2), 0u);
  }
}

TEST(Tmcm3216Restart, lss_reset_communication_of_an_unconfigured_node_takes_the_communication_restart_time) {
  Tmcm3216Rig rig(with_boot_delays());
  run_us(rig, Tmcm3216::kBootDelayUs);
  rig.can.take();
  // Unconfigured: 2705 = 255 stored, reset node.
  EXPECT_EQ(rig.download(0x2705, 0, 255, 1), 0u);
  EXPECT_EQ(rig.download(0x2706, 1, Tmcm3216::kSaveSignature), 0u);
  rig.nmt(0x81, 1);
  EXPECT_TRUE(run_us(rig, Tmcm3216::kBootDelayUs).empty()) << "an unconfigured node sends no boot-up";
  EXPECT_FALSE(rig.device->configured());
  rig.send(frame_of(0x7E5, {0x04, 0x01, 0, 0, 0, 0, 0, 0}));              // switch state global: configuration
  EXPECT_EQ(rig.send(frame_of(0x7E5, {0x11, 0x07, 0, 0, 0, 0, 0, 0})).size(), 1u);  // node ID 7
  EXPECT_TRUE(rig.send(frame_of(0x7E5, {0x04, 0x00, 0, 0, 0, 0, 0, 0})).empty());  // waiting: reset communication
  EXPECT_TRUE(rig.device->restarting());
  EXPECT_TRUE(run_us(rig, Tmcm3216::kCommunicationBootDelayUs - 1000).empty());
  EXPECT_TRUE(has_bootup(run_us(rig, 1000), 7));
}

}  // namespace
}  // namespace motwin::testing
