// The TMCM-1636 with its CANopen firmware (modules::tmcm1636::Tmcm1636Canopen: the generic
// canopen::Node, the CiA-402 drive and the TMCL firmware's servo axis following the drive's
// demand) on its simulated board, driven only through its public API: CAN frames in (a bring-up
// chosen by one byte: NMT start, a mode, a usable profile, shutdown / switch on / enable
// operation; then SDO downloads biased to the drive objects, table 228's commands and the modes,
// uploads and downloads of any object of the table at its range edges, raw SDO requests (mostly on
// real objects, sometimes garbage), RPDOs on the default COB-IDs, SYNC, NMT, node-guarding remote
// frames, LSS master frames, any identifier), board inputs (switches, supply, loads) and control
// ticks of 50 us in between. The motor is the ideal one, or for one input in eight the reference
// motor of PyTrinamic's examples (qbl4208-61-04-013, on the physical plant, its start-up settings
// in the image as `motwin serve --motor` writes them).
//
// Invariants:
// - the statusword (6041) holds a valid state coding of table 234 and the one of the drive's PDS
//   state; the PDS has power enabled exactly in OPERATION ENABLED, QUICK STOP ACTIVE and FAULT
//   REACTION ACTIVE (power_drive_system.h);
// - the power stage is off: the axis is not driver-enabled once the PDS has been in a state without
//   power for a drive period (the drive runs once a millisecond and hands the axis its demand
//   then, docs/tmcm-1636-canopen.md); the ideal motor does not move across a tick with the driver
//   off before and after it (a homing's position assignment, which sets its counter without
//   motion, aside);
// - every frame on 0x580 + node ID is the response the SDO client expects (fuzz::SdoClientView,
//   as in canopen_sdo), an expedited download acknowledged without abort reads back as written
//   and an aborted one changes nothing;
// - no frame on 0x7E4 ever (the firmware has no LSS), and an LSS frame changes neither the NMT
//   state nor the node ID;
// - a node-guarding request (remote frame on 0x700 + node ID) is answered exactly when the
//   heartbeat is not produced (1017 = 0), with one byte: the NMT state and a toggle bit that
//   alternates from 0 after each boot-up; every frame on 0x701..0x77F is one byte with an NMT
//   state code;
// - every frame sent is a classic frame of at most 8 bytes;
// - the drive's demand and ramp velocities, the axis' reference velocity and the plant's angle,
//   speed, currents and bus voltage stay finite;
// - every writable numeric object holds a value inside its row's range.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "canopen_checks.h"
#include "core/cia402/power_drive_system.h"
#include "core/modules/tmcm1636/tmcm1636_canopen.h"
#include "host/modules/tmcm1636/tmcm1636_startup_image.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace {

using namespace motwin;
using fuzz::check_dictionary_ranges;
using fuzz::trace;
using cia402::PdsState;
using Device = modules::tmcm1636::Tmcm1636Canopen;
using Nvm = board::RamNonVolatileMemory<Device::kNvmSize>;

constexpr const char* kPhysicalMotor = "qbl4208-61-04-013";
constexpr uint32_t kTickUs = modules::tmcm1636::kControlTickUs;
constexpr int kTickBudget = 4000;  // 200 ms of the ideal motor per input
constexpr int kPhysicalTickBudget = 1000;  // 50 ms of the physical one (see fuzz/README.md, Speed)

// The objects a master writes to run the drive, with the sub-indices they have (a range).
struct DriveObject {
  uint16_t index;
  uint8_t first_sub;
  uint8_t last_sub;
};
constexpr DriveObject kDriveObjects[] = {
    {0x6040, 0, 0}, {0x6040, 0, 0}, {0x6040, 0, 0}, {0x6060, 0, 0}, {0x6060, 0, 0}, {0x607A, 0, 0},
    {0x60FF, 0, 0}, {0x6071, 0, 0}, {0x6081, 0, 0}, {0x6083, 0, 0}, {0x6084, 0, 0}, {0x6085, 0, 0},
    {0x6098, 0, 0}, {0x6099, 1, 2}, {0x609A, 0, 0}, {0x607C, 0, 0}, {0x605A, 0, 0}, {0x6072, 0, 0},
    {0x60C2, 1, 2}, {0x6065, 0, 0}, {0x6067, 0, 0}, {0x607D, 1, 2}, {0x2005, 0, 0}, {0x2057, 0, 0},
    {0x2058, 0, 0}, {0x2080, 2, 2}};
// Table 228's commands (shutdown, switch on, enable operation, disable voltage, quick stop,
// disable operation, fault reset) with the mode bits 4..6, 8 (halt) around them.
constexpr uint16_t kControlwords[] = {0x0006, 0x0007, 0x000F, 0x0000, 0x0002, 0x0007, 0x0080, 0x001F,
                                      0x000F, 0x010F, 0x005F, 0x003F, 0x000B, 0x008F, 0x002F};
// pp, pv, hm, csp, csv, cst, then modes the firmware refuses.
constexpr int8_t kModes[] = {1, 3, 6, 8, 9, 10, 0, -1, 2, 7, 4};
// The methods the firmware supports (17, 18, 19, 21, 35), then some it refuses.
constexpr int8_t kHomingMethods[] = {17, 18, 19, 21, 35, 0, 1, 37, -1};
// LSS master command specifiers (canopen_lss), which the firmware must ignore.
constexpr uint8_t kLssCommands[] = {0x04, 0x40, 0x41, 0x42, 0x43, 0x11, 0x13, 0x15,
                                    0x17, 0x5A, 0x5B, 0x5C, 0x5D, 0x5E, 0x51};

FUZZ_UNTRACED bool powered(PdsState state) {
  return state == PdsState::kOperationEnabled || state == PdsState::kQuickStopActive ||
         state == PdsState::kFaultReactionActive;
}

// Table 234: the state a statusword codes, if any.
bool valid_state_coding(uint16_t sw) {
  const uint16_t a = sw & 0x4F, b = sw & 0x6F;
  return a == 0x00 || a == 0x40 || b == 0x21 || b == 0x23 || b == 0x27 || b == 0x07 || a == 0x0F || a == 0x08;
}

// The module on its sim board (the ideal motor, or the physical one with its start-up image), on a
// RAM EEPROM, powered up; one per input (fuzz::fresh_rig).
template <bool kPhysical>
struct CanopenRig {
  static const sim::MotorDescription& motor() {
    static const sim::MotorDescription description = *sim::motor_preset(kPhysicalMotor);
    return description;
  }
  // The factory image, with the motor's start-up settings for the physical one: once per process.
  static const std::array<uint8_t, Device::kNvmSize>& image() {
    static const std::array<uint8_t, Device::kNvmSize> bytes = [] {
      std::array<uint8_t, Device::kNvmSize> out{};
      Device::format_factory_image(out.data(), out.size());
      if constexpr (kPhysical) host::write_tmcm1636_canopen_startup_image(motor(), out.data(), out.size());
      return out;
    }();
    return bytes;
  }

  Nvm nvm;
  struct ImageCopied {  // in place before the module is constructed
    explicit ImageCopied(Nvm& memory) { std::memcpy(memory.mutable_data(), image().data(), image().size()); }
  } image_copied{nvm};
  fuzz::RecordingCan can;
  sim::Tmcm1636SimIo io;
  sim::Tmcm1636SimBoard board;
  Device device{nvm, can, board.io()};

  CanopenRig()
    requires(!kPhysical)
      : board(io) {
    device.power_up();
  }
  CanopenRig()
    requires(kPhysical)
      : board(io, motor()) {
    device.axis().attach_power_stage(board.power_stage());
    device.power_up();
  }

  std::vector<int64_t> state() {
    std::vector<int64_t> values = fuzz::dictionary_state(device, nvm);
    if (const sim::Tmcm1636Plant* plant = board.plant()) {
      for (double v : {plant->mechanical_angle_rad(), plant->speed_rad_s(), plant->bus_voltage(), plant->iq_amps()}) {
        int64_t bits = 0;
        std::memcpy(&bits, &v, sizeof(bits));
        values.push_back(bits);
      }
    }
    return values;
  }
};

// A numeric object as an upload gives it (0 if it has none), through the checks' untraced lookup.
uint32_t read_u32(Device& device, uint16_t index, uint8_t sub) {
  canopen::ObjectRef ref;
  if (!fuzz::ObjectLookup::of(device).find(index, sub, ref) || !canopen::is_numeric(ref.info->type)) return 0;
  uint8_t bytes[8] = {};
  fuzz::read_numeric(device, ref, bytes);
  return fuzz::le32(bytes);
}

// What the target watches across steps and ticks.
struct Watch {
  // Control ticks run since the PDS was last seen in a state with power (see check_power).
  int unpowered_ticks = 0;
  // Node guarding: the toggle bit the next answer must carry.
  bool guard_toggle = false;
};

// The PDS state against the statusword and the power stage; `ticked`: a control tick just ran.
FUZZ_UNTRACED void check_power(const Device& device, Watch& watch, bool ticked) {
  const PdsState state = device.drive().state();
  const bool on = powered(state);
  if (device.drive().pds().power_enabled() != on) {
    FUZZ_CHECK(false, "PDS state %d with power_enabled() %d", static_cast<int>(state), device.drive().pds().power_enabled());
  }
  if (on) {
    watch.unpowered_ticks = 0;
  } else if (ticked) {
    ++watch.unpowered_ticks;
  }
  if (device.axis().state.driver_enabled != 0 && watch.unpowered_ticks >= static_cast<int>(Device::kDriveTicks)) {
    FUZZ_CHECK(false, "the axis is driver-enabled %d ticks into PDS state %d", watch.unpowered_ticks,
               static_cast<int>(state));
  }
}

FUZZ_UNTRACED void check_finite(const Device& device, const sim::Tmcm1636SimBoard& board) {
  const double values[] = {device.drive().velocity_pps(), device.drive().demand().velocity_exact_pps,
                           device.axis().ramp().velocity()};
  for (double v : values) {
    if (!std::isfinite(v)) FUZZ_CHECK(false, "a drive or axis velocity is %g", v);
  }
  if (const sim::Tmcm1636Plant* plant = board.plant()) {
    const double readings[] = {plant->mechanical_angle_rad(), plant->speed_rad_s(), plant->id_amps(), plant->iq_amps(),
                               plant->bus_voltage()};
    for (double v : readings) {
      if (!std::isfinite(v)) FUZZ_CHECK(false, "a plant reading is %g", v);
    }
  }
}

// Up to `ticks` control ticks of module and board within the input's budget, with the power and
// standstill invariants checked around each. The loop and the checks are left out of libFuzzer's
// tracing (FUZZ_UNTRACED: their comparisons guide nothing; the module's and the board's ticks stay
// as they are).
FUZZ_UNTRACED void run_ticks(Device& device, sim::Tmcm1636SimBoard& board, Watch& watch, int ticks,
                             int& ticks_left) {
  const bool ideal = board.plant() == nullptr;
  for (int i = 0; i < ticks && ticks_left > 0; ++i, --ticks_left) {
    const bool off_before = device.axis().state.driver_enabled == 0;
    const int32_t position_before = device.axis().actual_position();
    const int32_t reading_before = device.drive().position_actual();
    board.before_tick();
    device.tick();
    board.after_tick(static_cast<double>(kTickUs) * 1e-6);
    check_power(device, watch, true);
    if (ideal && off_before && device.axis().state.driver_enabled == 0 &&
        device.axis().actual_position() != position_before) {
      // Not a motion: a homing's position assignment sets the counter to the position the drive
      // assigned, which its reading (6064) has shown since (homing 35 attains at the controlword's
      // write, and a disable voltage may follow before the drive's next run takes it over).
      const bool assigned = device.drive().homing().attained() &&
                            device.axis().actual_position() == device.axis_position(reading_before);
      if (!assigned) {
        FUZZ_CHECK(false, "the ideal motor moved from %d to %d with the driver off (PDS state %d)", position_before,
                   device.axis().actual_position(), static_cast<int>(device.drive().state()));
      }
    }
    check_finite(device, board);
  }
}

void check_statusword(Device& device) {
  static const canopen::ObjectRef statusword = [&device] {
    canopen::ObjectRef ref;
    FUZZ_CHECK(device.dictionary().find(0x6041, 0, ref) == canopen::SdoAbort::kNone, "no statusword");
    return ref;
  }();
  const auto sw = static_cast<uint16_t>(device.dictionary().value(statusword));
  FUZZ_CHECK(valid_state_coding(sw), "statusword %04x is no state of table 234", sw);
  const PdsState state = std::as_const(device).drive().state();
  const uint16_t expected = cia402::state_bits(state);
  FUZZ_CHECK((sw & 0x6F) == (expected & 0x6F), "statusword %04x, PDS state %d codes %04x", sw,
             static_cast<int>(state), expected);
}

template <bool kPhysical>
void run_input(FuzzedDataProvider& in, uint8_t bring_up) {
  const auto rig_in_place = fuzz::fresh_rig<CanopenRig<kPhysical>>();
  CanopenRig<kPhysical>& rig = *rig_in_place;
  fuzz::RecordingCan& can = rig.can;
  sim::Tmcm1636SimBoard& board = rig.board;
  Device& device = rig.device;
  can.frames.clear();
  const auto signals = sim::Tmcm1636SimBoard::signal_table();
  fuzz::SdoClientView client(device);
  Watch watch;
  int ticks_left = kPhysical ? kPhysicalTickBudget : kTickBudget;

  // A bring-up most inputs start from, as a master does it (frames in): NMT start, a mode, a
  // profile that moves (6081 1000 rpm, 6083 / 6084 / 6085 and 609A 5000 rpm/s, 6099 300 / 60 rpm),
  // shutdown / switch on / enable operation. Bits 0-3: the mode (kModes; 11..15 none), 4: the
  // profile, 5: enable, 6: no NMT start.
  std::vector<can::CanFrame> prelude;
  if ((bring_up & 0x40) == 0) {
    can::CanFrame start;
    start.dlc = 2;
    start.data[0] = 0x01;
    prelude.push_back(start);
  }
  if ((bring_up & 0x0F) < std::size(kModes)) prelude.push_back(fuzz::expedited_download(device, 0x6060, 0, kModes[bring_up & 0x0F]));
  if (bring_up & 0x10) {
    struct Setting {
      uint16_t index;
      uint8_t sub;
      int64_t value;
    };
    constexpr Setting kProfile[] = {{0x6081, 0, 1000}, {0x6083, 0, 5000}, {0x6084, 0, 5000}, {0x6085, 0, 5000},
                                    {0x609A, 0, 5000}, {0x6099, 1, 300},  {0x6099, 2, 60}};
    for (const Setting& s : kProfile) prelude.push_back(fuzz::expedited_download(device, s.index, s.sub, s.value));
  }
  if (bring_up & 0x20) {
    for (uint16_t cw : {0x0006, 0x0007, 0x000F}) prelude.push_back(fuzz::expedited_download(device, 0x6040, 0, cw));
  }
  for (const can::CanFrame& frame : prelude) {
    trace("->", frame);
    device.receive(frame);
    device.process(0);
  }
  can.frames.clear();
  check_power(device, watch, false);

  for (int step = 0; step < 160 && in.remaining_bytes() > 0; ++step) {
    can::CanFrame frame;
    bool send = true;
    bool lss = false;
    client.before(nullptr, 0);
    switch (in.ConsumeIntegralInRange<int>(0, 14)) {
      case 0:
        frame = fuzz::drive_nmt_command(in, device.node_id());
        break;
      case 1:
      case 2:
      case 3: {  // a drive object
        const DriveObject& object = kDriveObjects[in.ConsumeIntegralInRange<size_t>(0, std::size(kDriveObjects) - 1)];
        const uint8_t sub = in.ConsumeIntegralInRange<uint8_t>(object.first_sub, object.last_sub);
        int64_t value;
        if (object.index == 0x6040) {
          value = kControlwords[in.ConsumeIntegralInRange<size_t>(0, std::size(kControlwords) - 1)];
        } else if (object.index == 0x6060) {
          value = kModes[in.ConsumeIntegralInRange<size_t>(0, std::size(kModes) - 1)];
        } else if (object.index == 0x6098) {
          value = kHomingMethods[in.ConsumeIntegralInRange<size_t>(0, std::size(kHomingMethods) - 1)];
        } else {
          value = in.ConsumeBool() ? in.ConsumeIntegralInRange<int64_t>(-200'000, 200'000) : in.ConsumeIntegral<int32_t>();
        }
        frame = fuzz::expedited_download(device, object.index, sub, value);
        break;
      }
      case 4: {  // any object of the table, at its range edges or any value (downloads), or an upload
        const auto rows = device.dictionary().rows();
        const auto& info = rows[in.ConsumeIntegralInRange<size_t>(0, rows.size() - 1)].info;
        const int64_t value = in.PickValueInArray({info.min, info.max, info.default_value, info.max + 1, info.min - 1,
                                                   static_cast<int64_t>(in.ConsumeIntegral<int32_t>())});
        frame = fuzz::expedited_download(device, info.index, info.sub, value);
        if (in.ConsumeBool()) frame.data[0] = 0x40;  // initiate upload
        break;
      }
      case 5:  // a raw SDO request: any command specifier and bytes, mostly on a real object
        frame = fuzz::raw_sdo_request(in, device, 1);
        break;
      case 6:  // an RPDO on its default COB-ID (6040; 6040 + 6060; 6040 + 607A; 6040 + 60FF)
        frame = fuzz::drive_rpdo_frame(in, device.node_id(), kControlwords, kModes);
        break;
      case 7:  // SYNC
        frame = fuzz::sync_frame(in);
        break;
      case 8: {  // node guarding: a remote frame on 0x700 + node ID (or a heartbeat of another node)
        const bool other = in.ConsumeIntegralInRange<int>(0, 7) == 0;
        frame.id = 0x700u + (other ? in.ConsumeIntegralInRange<uint32_t>(0, 127) : device.node_id());
        frame.rtr = in.ConsumeIntegralInRange<int>(0, 7) != 0;
        frame.dlc = in.ConsumeIntegralInRange<uint8_t>(0, 8);
        frame.data[0] = in.PickValueInArray({0x00, 0x04, 0x05, 0x7F});
        break;
      }
      case 9: {  // an LSS master frame, which the firmware ignores
        frame.id = canopen::kLssMasterCobId;
        frame.dlc = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegralInRange<uint8_t>(0, 8) : 8;
        for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
        if (in.ConsumeBool()) frame.data[0] = in.PickValueInArray(kLssCommands);
        lss = true;
        break;
      }
      case 10: {  // any identifier
        frame = fuzz::any_frame(in);
        lss = frame.id == canopen::kLssMasterCobId;
        break;
      }
      case 11: {  // a board input: switches, supply, temperature, loads
        const sim::SignalInfo& signal = signals[in.ConsumeIntegralInRange<size_t>(0, signals.size() - 1)];
        double value = in.ConsumeFloatingPointInRange<double>(signal.min, signal.max);
        if (signal.whole_numbers_only) value = static_cast<double>(static_cast<int64_t>(value));
        if (sim::check_signal_value(signal, value).ok()) board.set_input(signal.name, value);
        send = false;
        break;
      }
      default: {  // control ticks
        send = false;
        const int ticks = in.ConsumeIntegralInRange<int>(1, 1000);
        client.before(nullptr, static_cast<uint32_t>(std::min(ticks, ticks_left)) * kTickUs);
        run_ticks(device, board, watch, ticks, ticks_left);
        break;
      }
    }

    const uint8_t node_before = device.node_id();
    const canopen::NmtState nmt_before = device.nmt_state();
    const bool guarding_request = send && frame.rtr && !frame.extended && frame.id == 0x700u + node_before;
    const bool heartbeat_produced = guarding_request && read_u32(device, 0x1017, 0) != 0;
    if (send) {
      trace("->", frame);
      client.before(&frame, 0);
      device.receive(frame);
      device.process(0);
    }
    int guarding_answers = 0;
    for (const can::CanFrame& out : can.frames) {
      trace("  <-", out);
      FUZZ_CHECK(!out.extended && !out.rtr && out.dlc <= 8 && out.id <= 0x7FF, "frame %x with dlc %u", out.id, out.dlc);
      FUZZ_CHECK(out.id != 0x7E4, "an LSS answer %02x", out.data[0]);
      if (out.id > 0x700 && out.id <= 0x77F) {
        const uint8_t code = out.data[0] & 0x7F;
        FUZZ_CHECK(out.dlc == 1 && (code == 0x00 || code == 0x04 || code == 0x05 || code == 0x7F),
                   "error control frame %x with dlc %u, %02x", out.id, out.dlc, out.data[0]);
        if (guarding_request && !heartbeat_produced && out.id == 0x700u + node_before) {
          ++guarding_answers;
          const uint8_t expected =
              static_cast<uint8_t>((watch.guard_toggle ? 0x80u : 0u) | static_cast<uint8_t>(nmt_before));
          FUZZ_CHECK(out.data[0] == expected, "node guarding answer %02x, %02x expected", out.data[0], expected);
          watch.guard_toggle = !watch.guard_toggle;
        } else {
          FUZZ_CHECK((out.data[0] & 0x80) == 0, "error control frame %02x with the toggle bit, not to a request",
                     out.data[0]);
          if (out.data[0] == 0x00) watch.guard_toggle = false;  // a boot-up: reset communication
        }
      }
    }
    if (guarding_request) {
      const bool answered = !heartbeat_produced && nmt_before != canopen::NmtState::kInitializing;
      FUZZ_CHECK(guarding_answers == (answered ? 1 : 0), "%d answers to a node guarding request (1017 %s)",
                 guarding_answers, heartbeat_produced ? "set" : "0");
    }
    if (lss) {
      FUZZ_CHECK(device.node_id() == node_before && device.nmt_state() == nmt_before,
                 "an LSS frame changed the node (ID %u -> %u, NMT %02x -> %02x)", node_before, device.node_id(),
                 static_cast<unsigned>(nmt_before), static_cast<unsigned>(device.nmt_state()));
    }
    client.after(can.frames);
    can.frames.clear();
    check_power(device, watch, false);
    check_finite(device, board);
    check_statusword(device);
    if (step % 16 == 15) check_dictionary_ranges(device);
  }
  check_dictionary_ranges(device);
  if (std::getenv("MOTWIN_FUZZ_TRACE") != nullptr) {
    std::fprintf(stderr, "PDS state %d, mode %d, demand %d, axis at %d, driver %d\n",
                 static_cast<int>(device.drive().state()), device.drive().mode_display(),
                 device.drive().position_demand(), device.axis().actual_position(),
                 device.axis().state.driver_enabled);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  // The first value (the input's last byte) is the bring-up, the second the motor: the physical
  // one when its bits 0-2 are all set (one input in eight).
  const uint8_t bring_up = in.ConsumeIntegral<uint8_t>();
  if ((in.ConsumeIntegral<uint8_t>() & 7) == 7) {
    run_input<true>(in, bring_up);
  } else {
    run_input<false>(in, bring_up);
  }
  return 0;
}
