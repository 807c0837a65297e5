// The CAN plumbing every CANopen module shares (host/canopen_sim_module.h), on a fake firmware
// and board: the node's configuration from the options, the start-up before `ready`, frames
// between the bus and the firmware, the controller's status from the bus, the tick loop, and a
// board over separate I/O (as the TMCM-1636's is).
#include <gtest/gtest.h>

#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "host/can_bus.h"
#include "host/canopen_sim_module.h"
#include "sim/general_io.h"
#include "sim/signals.h"

namespace motwin::host {
namespace {

constexpr sim::SignalInfo kFakeSignals[] = {{"LEVEL", 0, 1, true, "a level"}};

// A board holding its own I/O: it samples LEVEL before each tick and logs the firmware's output.
class FakeBoard final : public sim::LoggingSignalBoard {
 public:
  static std::span<const sim::SignalInfo> signal_table() { return kFakeSignals; }
  std::span<const sim::SignalInfo> input_signals() const override { return signal_table(); }
  void set_input(std::string_view, double value) override { level_ = value; }
  std::optional<double> read_signal(std::string_view) const override { return level_; }

  void before_tick() { sensed_level = level_; }
  void after_tick(double dt_s) { advanced_s += dt_s; }
  void drive_output(int32_t level) { output_changes_.record("OUT", level); }

  double sensed_level = -1;
  double advanced_s = 0;

 private:
  double level_ = 0;
};

// A board over separate I/O (sim::SimBoardOverIo): the I/O stamps the output changes.
class FakeIo final : public sim::LoggingSignalBoard {
 public:
  std::span<const sim::SignalInfo> input_signals() const override { return kFakeSignals; }
  void set_input(std::string_view, double value) override { level = value; }
  std::optional<double> read_signal(std::string_view) const override { return level; }
  void drive_output(int32_t value) { output_changes_.record("OUT", value); }
  double level = 0;
};

class FakeBoardOverIo final : public sim::SimBoardOverIo<FakeBoardOverIo, FakeIo> {
 public:
  static std::span<const sim::SignalInfo> signal_table() { return kFakeSignals; }
  explicit FakeBoardOverIo(FakeIo& io) : SimBoardOverIo(io) {}
  void set_input(std::string_view name, double value) override { io_.set_input(name, value); }
  std::optional<double> read_signal(std::string_view name) const override { return io_.read_signal(name); }
  void before_tick() { sensed_level = io_.level; }
  void after_tick(double dt_s) { advanced_s += dt_s; }
  void drive_output(int32_t level) { io_.drive_output(level); }
  double sensed_level = -1;
  double advanced_s = 0;
};

// The firmware: logs what the host runtime does to it, answers each frame received with its ID
// + 1 once processed, and drives OUT to the tick count.
template <class Board>
class FakeNodeDevice {
 public:
  static constexpr std::string_view kName = "fake-node";
  static constexpr std::string_view kFirmwareVersion = "FAKE V1.00";
  static constexpr uint32_t kNvmLayoutVersion = 1;
  static constexpr size_t kNvmSize = 16;
  static constexpr uint32_t kBootDelayUs = 300'000;
  static constexpr uint32_t kCommunicationBootDelayUs = 50'000;

  static void format_factory_image(uint8_t* image, size_t size) { std::memset(image, 0xA5, size); }

  FakeNodeDevice(board::NonVolatileMemory& image, board::CanController& controller, Board& sim_board,
                 const canopen::NodeConfig& node_config)
      : nvm(image), can(controller), board(sim_board), config(node_config), level_at_construction(sim_board.sensed_level) {}

  void power_up() { log.push_back("power_up"); }
  void receive(const can::CanFrame& frame) { received.push_back(frame); }
  void process(uint32_t elapsed_us) {
    log.push_back("process " + std::to_string(elapsed_us));
    for (can::CanFrame frame : received) {
      frame.id += 1;
      can.transmit(frame);
    }
    received.clear();
  }
  void tick() { board.drive_output(static_cast<int32_t>(++ticks)); }
  uint16_t bit_rate_kbit() const { return bit_rate; }

  board::NonVolatileMemory& nvm;
  board::CanController& can;
  Board& board;
  canopen::NodeConfig config;
  double level_at_construction;
  std::vector<std::string> log;
  std::vector<can::CanFrame> received;
  uint64_t ticks = 0;
  uint16_t bit_rate = 1000;
};

using FakeDevice = FakeNodeDevice<FakeBoard>;
using FakeModule = CanopenSimModule<FakeDevice, FakeBoard, 50, 50e-6>;
using FakeDeviceOverIo = FakeNodeDevice<FakeBoardOverIo>;
using FakeModuleOverIo = CanopenSimModule<FakeDeviceOverIo, FakeBoardOverIo, 250, 250e-6, FakeIo>;

}  // namespace

// What a module's own make() is: its checks, then the board and the device.
template <>
MakeModuleResult FakeModule::make(const ModuleOptions& options) {
  return power_up_on_bus(
      options, [] { return std::make_unique<FakeBoard>(); },
      [](board::NonVolatileMemory& nvm, board::CanController& can, FakeBoard& board, const canopen::NodeConfig& config) {
        return std::make_unique<FakeDevice>(nvm, can, board, config);
      });
}

template <>
MakeModuleResult FakeModuleOverIo::make(const ModuleOptions& options) {
  return power_up_on_bus(
      options, [](FakeIo& io) { return std::make_unique<FakeBoardOverIo>(io); },
      [](board::NonVolatileMemory& nvm, board::CanController& can, FakeBoardOverIo& board,
         const canopen::NodeConfig& config) { return std::make_unique<FakeDeviceOverIo>(nvm, can, board, config); });
}

namespace {

struct Recorder final : CanBusEndpoint {
  std::vector<can::CanFrame> frames;
  void on_frame(const can::CanFrame& frame, uint64_t) override { frames.push_back(frame); }
};

// The module a make() gave; a failed make() stops the test (its message in the output).
template <class Module>
Module& made(const MakeModuleResult& result) {
  if (!result) ADD_FAILURE() << result.error();
  return static_cast<Module&>(*result.value());
}

TEST(CanopenSimModule, is_configured_from_the_options_and_has_restarted_when_made) {
  ModuleOptions options;
  options.node_id = 5;
  options.initial_inputs = {{"LEVEL", 1}};
  const MakeModuleResult result = FakeModule::make(options);
  FakeModule& module = made<FakeModule>(result);
  const FakeDevice& device = module.device();
  EXPECT_EQ(device.config.node_id_switches, 5);
  EXPECT_EQ(device.config.serial_number, 1u) << "the default serial number";
  EXPECT_EQ(device.config.boot_delay_us, FakeDevice::kBootDelayUs);
  EXPECT_EQ(device.config.communication_boot_delay_us, FakeDevice::kCommunicationBootDelayUs);
  // Powered up, then its restart time passed, before anybody could be on the bus.
  EXPECT_EQ(device.log, (std::vector<std::string>{"power_up", "process 300000"}));
  EXPECT_EQ(device.level_at_construction, 1.0) << "the inputs are sampled before the firmware starts";
  EXPECT_EQ(module.nvm().size(), FakeDevice::kNvmSize);
  EXPECT_EQ(module.nvm().data()[0], 0xA5) << "a factory image";
  EXPECT_EQ(&device.nvm, &module.nvm());
  EXPECT_EQ(module.nvm_location(), "none");
  EXPECT_EQ(module.name(), "fake-node");
  EXPECT_EQ(module.firmware_version(), "FAKE V1.00");
  EXPECT_FALSE(module.has_tmcl());
  EXPECT_EQ(module.can_node(), &module);
  EXPECT_EQ(module.tick_period_us(), 50u);
  EXPECT_EQ(FakeModule::signal_table().size(), 1u);
  EXPECT_EQ(FakeModule::eeprom_identity().module_name, "fake-node");

  options.serial_number = 42;
  options.boot_delay_ms = 7;
  options.communication_boot_delay_ms = 3;
  const MakeModuleResult other = FakeModule::make(options);
  const FakeDevice& configured = made<FakeModule>(other).device();
  EXPECT_EQ(configured.config.serial_number, 42u);
  EXPECT_EQ(configured.config.boot_delay_us, 7000u);
  EXPECT_EQ(configured.config.communication_boot_delay_us, 3000u);
  EXPECT_EQ(configured.log.back(), "process 7000");

  options.node_id = 128;
  const MakeModuleResult refused = FakeModule::make(options);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error(), "node ID 128 is out of range (1..127)");
}

TEST(CanopenSimModule, answers_frames_within_the_bus_delivery_and_leaves_the_bus) {
  const MakeModuleResult result = FakeModule::make({});
  FakeModule& module = made<FakeModule>(result);
  FakeDevice& device = module.device();
  EXPECT_TRUE(device.can.transmit(can::make_frame(0x700, nullptr, 0))) << "on no bus: accepted, sent nowhere";
  EXPECT_EQ(device.can.status().error_state, board::CanErrorState::kErrorActive);

  CanBus bus;
  Recorder client;
  const CanBus::EndpointId client_id = bus.attach(client);
  module.connect(bus);
  const uint8_t request[] = {0x40, 0x00, 0x10, 0x00};
  bus.send(client_id, can::make_frame(0x605, request, 4));
  ASSERT_EQ(client.frames.size(), 1u);
  EXPECT_EQ(client.frames[0].id, 0x606u);
  EXPECT_EQ(client.frames[0].data[0], 0x40);
  EXPECT_EQ(device.log.back(), "process 0");

  // Its controller's rate decides whether it takes part; off speed, its transmissions fail
  // and its controller goes error-passive (TEC +8 a frame), as the bus sees it.
  EXPECT_EQ(module.controller_bit_rate(), 1'000'000u);
  bus.set_bit_rate(500'000);
  for (int i = 0; i < 16; ++i) device.can.transmit(can::make_frame(0x185, nullptr, 0));
  const board::CanControllerStatus status = device.can.status();
  EXPECT_EQ(status.error_state, board::CanErrorState::kErrorPassive);
  EXPECT_TRUE(status.warning);
  EXPECT_EQ(status.bus_off_recoveries, 0u);
  bus.set_bit_rate(1'000'000);

  module.disconnect();
  bus.send(client_id, can::make_frame(0x605, request, 4));
  EXPECT_EQ(client.frames.size(), 1u) << "off the bus";
  EXPECT_EQ(bus.endpoint_count(), 1u);
}

TEST(CanopenSimModule, runs_ticks_on_its_board_and_stamps_outputs_at_their_tick) {
  const MakeModuleResult result = FakeModule::make({});
  FakeModule& module = made<FakeModule>(result);
  module.run_ticks(3);
  EXPECT_EQ(module.device().ticks, 3u);
  EXPECT_EQ(module.tick_count(), 3u);
  EXPECT_EQ(module.sim_time_us(), 150u);
  EXPECT_DOUBLE_EQ(module.board().advanced_s, 3 * 50e-6);
  std::vector<sim::OutputChange> changes;
  module.signals().take_output_changes(changes);
  ASSERT_EQ(changes.size(), 3u);
  EXPECT_EQ(changes[0].sim_time_us, 0u);
  EXPECT_EQ(changes[2].sim_time_us, 100u);
  EXPECT_EQ(changes[2].level, 3);
}

TEST(CanopenSimModule, a_board_over_its_own_io_keeps_the_io_in_the_module) {
  ModuleOptions options;
  options.initial_inputs = {{"LEVEL", 1}};
  const MakeModuleResult result = FakeModuleOverIo::make(options);
  FakeModuleOverIo& module = made<FakeModuleOverIo>(result);
  EXPECT_EQ(module.io().level, 1.0);
  EXPECT_EQ(module.device().level_at_construction, 1.0);
  module.run_ticks(2);
  EXPECT_EQ(module.sim_time_us(), 500u);
  EXPECT_DOUBLE_EQ(module.board().advanced_s, 2 * 250e-6);
  std::vector<sim::OutputChange> changes;
  module.signals().take_output_changes(changes);
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[1].sim_time_us, 250u) << "stamped by the I/O's clock";
}

}  // namespace
}  // namespace motwin::host
