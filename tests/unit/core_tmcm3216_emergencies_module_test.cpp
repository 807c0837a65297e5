// The axis emergencies of the TMCM-3216 (table 365) in the module on its simulated board: driver
// flags from the board's fault signals reach the bus as the exact EMCY frames, faults hold the
// axis in FAULT until a fault reset finds them gone, warnings do not stop the axis; and the CAN
// controller's error states (EMCY 8120, bus-off stopping the axes, 8140) from its status().
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "board/can_controller.h"
#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "host/can_bus.h"
#include "host/module_registry.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"
#include "support/tmcm3216_board_rig.h"

namespace motwin::modules::tmcm3216 {
namespace {

using Bytes = std::array<uint8_t, 8>;

// Operational, with the EMCY frames of the start-up read.
struct EmcyRig : testing::Tmcm3216BoardRig {
  EmcyRig() {
    nmt(0x01);  // operational
    run_ms(2);
    emergencies();
  }
  int64_t read(uint16_t index) {
    canopen::ObjectRef ref;
    EXPECT_EQ(device->dictionary().find(index, 0, ref), canopen::SdoAbort::kNone);
    return ref.info == nullptr ? 0 : device->dictionary().value(ref);
  }
  void write(uint16_t index, int64_t value, uint8_t sub = 0) {
    canopen::ObjectRef ref;
    ASSERT_EQ(device->dictionary().find(index, sub, ref), canopen::SdoAbort::kNone);
    ASSERT_EQ(write_object(index, sub, value), canopen::SdoAbort::kNone);
  }
  void enable(uint16_t offset) {
    write(0x6060 + offset, 3);
    write(0x6040 + offset, 6);
    write(0x6040 + offset, 7);
    write(0x6040 + offset, 15);
    run_ms(1);
  }
};

void expect_frames(const std::vector<can::CanFrame>& frames, const std::vector<Bytes>& expected) {
  ASSERT_EQ(frames.size(), expected.size());
  for (size_t n = 0; n < frames.size(); ++n) {
    EXPECT_EQ(frames[n].dlc, 8);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(frames[n].data[i], expected[n][i]) << "frame " << n << " byte " << i;
  }
}

TEST(Tmcm3216EmergenciesModule, overtemperature_warns_then_faults_and_the_reset_waits_for_cooling) {
  EmcyRig rig;
  rig.enable(0x800);
  rig.board.set_input("AXIS1_DRIVER_TEMP", 130);
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x10, 0x43, 0x09, 1, 1, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x6841) & 0x6F, 0x27) << "a pre-warning leaves the axis enabled";
  rig.board.set_input("AXIS1_DRIVER_TEMP", 160);
  rig.run_ms(2);
  // The error carries the FAULT bits it sets (generic, temperature, device profile).
  expect_frames(rig.emergencies(), {{0x10, 0x43, 0x29, 0, 1, 0, 0, 0}});
  rig.run_ms(50);
  EXPECT_EQ(rig.read(0x6841) & 0x4F, 0x08);
  EXPECT_EQ(rig.read(0x1001), 0x29);  // generic, temperature, device profile (FAULT)
  // Still hot: the reset is refused and says why.
  rig.write(0x6840, 0x80);
  rig.run_ms(2);
  EXPECT_EQ(rig.read(0x6841) & 0x4F, 0x08);
  expect_frames(rig.emergencies(), {{0x10, 0x43, 0x29, 0, 1, 0, 0, 0}});
  rig.write(0x6840, 0x00);
  rig.board.set_input("AXIS1_DRIVER_TEMP", 25);
  rig.run_ms(2);
  EXPECT_TRUE(rig.emergencies().empty());
  rig.write(0x6840, 0x80);
  rig.run_ms(2);
  EXPECT_EQ(rig.read(0x6841) & 0x4F, 0x40);
  expect_frames(rig.emergencies(), {{0x00, 0x00, 0x00, 0, 1, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x1001), 0);
}

TEST(Tmcm3216EmergenciesModule, open_coil_is_a_warning_and_a_short_a_fault) {
  EmcyRig rig;
  rig.enable(0);
  rig.board.set_input("AXIS0_OPEN_COIL_A", 1);
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x00, 0x10, 0x01, 1, 0, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x6041) & 0x6F, 0x27);
  EXPECT_EQ(rig.read(0x1001), 0x01);
  rig.board.set_input("AXIS0_OPEN_COIL_A", 0);
  rig.enable(0x1000);
  rig.board.set_input("AXIS2_SHORT", 1);
  rig.run_ms(50);
  expect_frames(rig.emergencies(), {{0x11, 0x23, 0x23, 0, 2, 0, 0, 0}, {0x12, 0x23, 0x23, 0, 2, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x7041) & 0x4F, 0x08);
  EXPECT_EQ(rig.read(0x6041) & 0x6F, 0x27) << "axis 0 runs on";
}

TEST(Tmcm3216EmergenciesModule, undervoltage_names_every_axis_and_faults_the_powered_ones) {
  EmcyRig rig;
  rig.enable(0x800);
  rig.board.set_input("VSUPPLY", 5);
  rig.run_ms(20);
  // Each carries 1001 as its report leaves it: axis 0 (off) only warns, axis 1's fault sets the
  // FAULT bits, axis 2 (off) warns while axis 1 is in FAULT.
  expect_frames(rig.emergencies(), {{0x00, 0xFF, 0x05, 0, 0, 0, 0, 0},
                                    {0x00, 0xFF, 0x25, 0, 1, 0, 0, 0},
                                    {0x00, 0xFF, 0x25, 0, 2, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x6841) & 0x4F, 0x08) << "axis 1 ran: FAULT";
  EXPECT_EQ(rig.read(0x6041) & 0x4F, 0x40) << "axis 0 was off: no fault";
  // Axis 0 switched on with the supply still low: FAULT, FF00 again.
  rig.enable(0);
  rig.run_ms(20);
  EXPECT_EQ(rig.read(0x6041) & 0x4F, 0x08);
  expect_frames(rig.emergencies(), {{0x00, 0xFF, 0x25, 0, 0, 0, 0, 0}});
}

TEST(Tmcm3216EmergenciesModule, overtemperature_at_once_is_one_message) {
  EmcyRig rig;
  rig.enable(0);
  rig.board.set_input("AXIS0_DRIVER_TEMP", 160);  // pre-warning and error flags in one reading
  rig.run_ms(20);
  expect_frames(rig.emergencies(), {{0x10, 0x43, 0x29, 0, 0, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x6041) & 0x4F, 0x08);
}

TEST(Tmcm3216EmergenciesModule, software_limit_reports_ff01_with_the_manufacturer_bit) {
  EmcyRig rig;
  rig.write(0x607D, 2000, 2);  // max position limit
  rig.enable(0);
  rig.write(0x60FF, 20000);
  rig.run_ms(500);
  // pv stops on the limit: FF01 sub 1 with statusword bit 11, 1001 generic + manufacturer.
  EXPECT_EQ(rig.read(0x6064), 2000);
  expect_frames(rig.emergencies(), {{0x01, 0xFF, 0x81, 1, 0, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x1001), 0x81);
  EXPECT_EQ(rig.read(0x6041) & 0x086F, 0x0827) << "a limit is no fault";
  // Moving back inside: the warning goes (silently), 1001 with it.
  rig.write(0x60FF, -20000);
  rig.run_ms(100);
  EXPECT_TRUE(rig.emergencies().empty());
  EXPECT_EQ(rig.read(0x1001), 0);
}

TEST(Tmcm3216EmergenciesModule, error_passive_sends_8120_and_error_active_again_0000) {
  EmcyRig rig;
  rig.can.can_status.error_state = board::CanErrorState::kErrorPassive;
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x20, 0x81, 0x11, 0, 255, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x1001), 0x11);
  rig.run_ms(20);
  EXPECT_TRUE(rig.emergencies().empty()) << "one message while it lasts";
  rig.can.can_status.error_state = board::CanErrorState::kErrorActive;
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x00, 0x00, 0x00, 0, 255, 0, 0, 0}});
  EXPECT_EQ(rig.read(0x1001), 0);
  // An NMT reset communication forgets it; a state that lasts is reported anew.
  rig.can.can_status.error_state = board::CanErrorState::kErrorPassive;
  rig.run_ms(2);
  rig.emergencies();
  rig.nmt(0x82);
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x20, 0x81, 0x11, 0, 255, 0, 0, 0}});
}

TEST(Tmcm3216EmergenciesModule, bus_off_stops_the_running_axes_and_8140_follows_the_recovery) {
  EmcyRig rig;
  rig.enable(0x800);
  rig.write(0x68FF, 20000);
  rig.run_ms(100);
  ASSERT_NE(rig.read(0x686C), 0);
  rig.can.can_status.error_state = board::CanErrorState::kErrorPassive;
  rig.run_ms(2);
  expect_frames(rig.emergencies(), {{0x20, 0x81, 0x11, 0, 255, 0, 0, 0}});
  // Bus-off: nothing can be sent; the running axis stops on its fault reaction.
  rig.can.can_status.error_state = board::CanErrorState::kBusOff;
  rig.run_ms(300);
  EXPECT_TRUE(rig.emergencies().empty());
  EXPECT_EQ(rig.read(0x6841) & 0x4F, 0x08) << "axis 1 ran: FAULT";
  EXPECT_EQ(rig.read(0x686C), 0);
  EXPECT_EQ(rig.read(0x6041) & 0x4F, 0x40) << "axis 0 was off";
  EXPECT_EQ(rig.read(0x1001), 0x31);
  // Bus-on again: 8140, and one service tick later 0000 (the FAULT bits remain).
  rig.can.can_status.error_state = board::CanErrorState::kErrorActive;
  rig.can.can_status.bus_off_recoveries = 1;
  rig.run_ms(3);
  expect_frames(rig.emergencies(), {{0x40, 0x81, 0x31, 0, 255, 0, 0, 0}, {0x00, 0x00, 0x21, 0, 255, 0, 0, 0}});
  // The master resets the axis: 0000 with the motor.
  rig.write(0x6840, 0x80);
  rig.run_ms(2);
  EXPECT_EQ(rig.read(0x6841) & 0x4F, 0x40);
  expect_frames(rig.emergencies(), {{0x00, 0x00, 0x00, 0, 1, 0, 0, 0}});
  // A bus-off that began and ended between two polls still stops a running axis.
  rig.enable(0x1000);
  rig.write(0x70FF, 20000);
  rig.run_ms(50);
  rig.can.can_status.bus_off_recoveries = 2;
  rig.run_ms(300);
  EXPECT_EQ(rig.read(0x7041) & 0x4F, 0x08);
  const auto frames = rig.emergencies();
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames[0].data[0], 0x40);
  EXPECT_EQ(frames[0].data[1], 0x81);
}

// The same chain on the virtual bus: Tmcm3216VirtualModule::status() from CanBus::node_stats().
// An LSS-activated 500 kbit/s on a 1 Mbit/s bus: the heartbeats climb TEC to error-passive (8120,
// lost: off speed) and bus-off, which stops the running axis; with the bus at 500 kbit/s the
// controller recovers and 8140 is the first EMCY the master sees.
struct Listener final : host::CanBusEndpoint {
  std::vector<can::CanFrame> frames;
  void on_frame(const can::CanFrame& frame, uint64_t /*timestamp_us*/) override { frames.push_back(frame); }
};

TEST(Tmcm3216EmergenciesModule, bus_off_on_the_virtual_bus_stops_the_axis_and_8140_reaches_the_master) {
  host::ModuleOptions options;
  options.node_id = 5;
  options.log = [](const std::string&) {};
  host::MakeModuleResult made = host::make_module("tmcm-3216", options);
  ASSERT_TRUE(made) << made.error();
  auto& module = static_cast<host::Tmcm3216VirtualModule&>(**made);
  host::CanBus bus([&module] { return module.sim_time_us(); });
  bus.set_bit_rate(1'000'000);
  Listener master;
  const host::CanBus::EndpointId master_id = bus.attach(master);
  module.connect(bus);
  auto send = [&](uint32_t id, std::initializer_list<uint8_t> bytes) {
    can::CanFrame frame;
    frame.id = id;
    frame.dlc = static_cast<uint8_t>(bytes.size());
    size_t i = 0;
    for (uint8_t b : bytes) frame.data[i++] = b;
    bus.send(master_id, frame);
  };
  auto run_ms = [&](uint32_t ms) { module.run_ticks(uint64_t{ms} * 1000u / kTickUs); };
  send(0x605, {0x2B, 0x17, 0x10, 0x00, 0x01, 0x00, 0, 0});  // 1017 = 1 ms heartbeat
  send(0x000, {0x01, 5});
  send(0x605, {0x2F, 0x60, 0x60, 0x00, 3, 0, 0, 0});  // pv
  for (uint8_t cw : {6, 7, 15}) send(0x605, {0x2B, 0x40, 0x60, 0x00, cw, 0, 0, 0});
  send(0x605, {0x23, 0xFF, 0x60, 0x00, 0x20, 0x4E, 0, 0});  // 60FF = 20000
  run_ms(50);
  ASSERT_EQ(module.device().drive(0).state(), cia402::PdsState::kOperationEnabled);
  send(0x7E5, {0x04, 0x01, 0, 0, 0, 0, 0, 0});  // LSS: configuration state
  send(0x7E5, {0x13, 0x00, 0x02, 0, 0, 0, 0, 0});  // bit timing 500 kbit/s
  send(0x7E5, {0x15, 10, 0, 0, 0, 0, 0, 0});  // activate after 10 ms
  run_ms(20);
  // Off speed: 16 heartbeats to error-passive, 32 to bus-off.
  for (int ms = 0; ms < 100 && bus.node_stats(module)->error_state != host::CanErrorState::kBusOff; ++ms) run_ms(1);
  ASSERT_EQ(bus.node_stats(module)->error_state, host::CanErrorState::kBusOff);
  run_ms(1);
  EXPECT_NE(module.device().drive(0).state(), cia402::PdsState::kOperationEnabled) << "stopped at bus-off";
  EXPECT_EQ(module.device().error_register() & 0x10, 0x10);
  // The master's adapter follows: recovery after 128 x 11 bits (2.8 ms), then 8140.
  master.frames.clear();
  bus.set_bit_rate(500'000);
  run_ms(300);
  EXPECT_EQ(module.device().drive(0).state(), cia402::PdsState::kFault);
  std::vector<can::CanFrame> emcy;
  for (const can::CanFrame& f : master.frames) {
    if (f.id == 0x85) emcy.push_back(f);
  }
  expect_frames(emcy, {{0x40, 0x81, 0x31, 0, 255, 0, 0, 0}, {0x00, 0x00, 0x21, 0, 255, 0, 0, 0}});
  module.disconnect();
}

}  // namespace
}  // namespace motwin::modules::tmcm3216
