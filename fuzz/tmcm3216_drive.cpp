// The TMCM-3216 as a three-axis CiA-402 drive on its simulated board (ideal motors), driven only
// through its public API: CAN frames in (a bring-up chosen by one byte: NMT start, a mode and
// enable operation on some axes; then SDO downloads biased to the drive objects, the PDS
// commands of table 228 and the modes; uploads; RPDOs with controlwords; SYNC; NMT; any
// identifier), board inputs (switches, supply, loads) and motion ticks in between.
//
// Invariants:
// - every statusword (6041 of each axis) holds a valid state coding of table 234 and the one of
//   the axis' PDS state;
// - an axis whose PDS state has the drive function disabled (not ready, switch on disabled,
//   ready to switch on, switched on, fault) before and after a tick does not move its motor
//   (the driver's electrical angle stays);
// - every frame on 0x580 + node ID is the response the SDO client expects (fuzz::SdoClientView,
//   as in canopen_sdo), an expedited download acknowledged without abort reads back as written
//   and an aborted one changes nothing; every frame sent is a classic frame of at most 8 bytes;
// - every writable numeric object of every axis holds a value inside its row's range.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "canopen_checks.h"
#include "core/cia402/power_drive_system.h"
#include "sim/modules/tmcm3216/tmcm3216_sim_board.h"

namespace {

using namespace motwin;
using fuzz::check_dictionary_ranges;
using fuzz::trace;
using modules::tmcm3216::Tmcm3216;
using cia402::PdsState;

constexpr uint8_t kAxes = modules::tmcm3216::kAxisCount;

// The objects a master writes to run the drive (axis 0's index; + 0x800 per axis).
constexpr uint16_t kDriveObjects[] = {0x6040, 0x6040, 0x6040, 0x6060, 0x6060, 0x607A, 0x60FF, 0x6081, 0x6083,
                                      0x6084, 0x6085, 0x6098, 0x6099, 0x609A, 0x607C, 0x605A, 0x605D, 0x60C2};
// Table 228's commands (shutdown, switch on, enable operation, disable voltage, quick stop,
// disable operation, fault reset) with the mode bits 4..6, 8 (halt) around them.
constexpr uint16_t kControlwords[] = {0x0006, 0x0007, 0x000F, 0x0000, 0x0002, 0x0007, 0x0080,
                                      0x001F, 0x000F, 0x010F, 0x005F, 0x003F, 0x000B, 0x008F};
constexpr int8_t kModes[] = {1, 3, 6, 8, 9, 0, -1, 2, 7};

FUZZ_UNTRACED bool drive_function_disabled(PdsState state) {
  return state == PdsState::kNotReadyToSwitchOn || state == PdsState::kSwitchOnDisabled ||
         state == PdsState::kReadyToSwitchOn || state == PdsState::kSwitchedOn || state == PdsState::kFault;
}

// Table 234: the state a statusword codes, if any.
bool valid_state_coding(uint16_t sw) {
  const uint16_t a = sw & 0x4F, b = sw & 0x6F;
  return a == 0x00 || a == 0x40 || b == 0x21 || b == 0x23 || b == 0x27 || b == 0x07 || a == 0x0F || a == 0x08;
}

void check_statuswords(Tmcm3216& device) {
  // Each axis' 6041 as find() answers for it, once per process (the object table is constant).
  static const auto statusword_refs = [&device] {
    std::array<canopen::ObjectRef, kAxes> refs{};
    for (uint8_t axis = 0; axis < kAxes; ++axis) {
      FUZZ_CHECK(device.dictionary().find(static_cast<uint16_t>(0x6041 + axis * 0x800), 0, refs[axis]) ==
                     canopen::SdoAbort::kNone,
                 "no statusword for axis %u", axis);
    }
    return refs;
  }();
  for (uint8_t axis = 0; axis < kAxes; ++axis) {
    const auto sw = static_cast<uint16_t>(device.dictionary().value(statusword_refs[axis]));
    FUZZ_CHECK(valid_state_coding(sw), "axis %u statusword %04x is no state of table 234", axis, sw);
    const PdsState state = std::as_const(device).drive(axis).state();
    const uint16_t expected = cia402::state_bits(state);
    FUZZ_CHECK((sw & 0x6F) == (expected & 0x6F), "axis %u statusword %04x, PDS state %d codes %04x", axis, sw,
               static_cast<int>(state), expected);
  }
}

// Up to `ticks` motion ticks of module and board within the input's budget, with the
// motor-standstill invariant checked around each: an axis whose PDS state has the drive
// function disabled before and after a tick does not move its motor. The loop and the checks are
// left out of libFuzzer's tracing (FUZZ_UNTRACED: their comparisons of loop counters, states and
// angles, a tenth of the target's time, guide nothing; the module's and the board's ticks stay as
// they are). The states are read through the const accessors: the mutable ones wake resting axes
// (a full tick each).
FUZZ_UNTRACED void run_ticks(Tmcm3216& device, sim::Tmcm3216SimBoard& board, int ticks, int& ticks_left) {
  const Tmcm3216& view = device;
  const board::Tmcm3216Board& stages = std::as_const(board).board();
  const modules::tmcm3216::Tmcm3216Drive* drives[kAxes];
  for (uint8_t axis = 0; axis < kAxes; ++axis) drives[axis] = &view.drive(axis);
  for (int i = 0; i < ticks && ticks_left > 0; ++i, --ticks_left) {
    PdsState before[kAxes];
    uint32_t angle[kAxes];
    for (uint8_t axis = 0; axis < kAxes; ++axis) {
      before[axis] = drives[axis]->state();
      angle[axis] = stages.axes[axis].drive.electrical_angle;
    }
    board.before_tick();
    device.tick();
    board.after_tick(modules::tmcm3216::kTickUs * 1e-6);
    for (uint8_t axis = 0; axis < kAxes; ++axis) {
      const PdsState after = drives[axis]->state();
      if (drive_function_disabled(before[axis]) && drive_function_disabled(after) &&
          stages.axes[axis].drive.electrical_angle != angle[axis]) {
        FUZZ_CHECK(false, "axis %u moved its motor in PDS state %d", axis, static_cast<int>(after));
      }
    }
  }
}

// The module on its sim board, on a RAM EEPROM with the factory image, powered up; one per input
// (fuzz::fresh_rig).
struct DriveRig {
  fuzz::Tmcm3216Nvm nvm;
  struct FactoryImage {  // in place before the module is constructed
    explicit FactoryImage(fuzz::Tmcm3216Nvm& memory) {
      const auto& image = fuzz::factory_image<Tmcm3216, Tmcm3216::kNvmSize>();
      std::memcpy(memory.mutable_data(), image.data(), image.size());
    }
  } factory_image_copied{nvm};
  fuzz::RecordingCan can;
  sim::Tmcm3216SimBoard board;
  Tmcm3216 device{nvm, can, board.board()};

  DriveRig() { device.power_up(); }
  std::vector<int64_t> state() { return fuzz::dictionary_state(device, nvm); }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  const auto rig_in_place = fuzz::fresh_rig<DriveRig>();
  DriveRig& rig = *rig_in_place;
  fuzz::RecordingCan& can = rig.can;
  sim::Tmcm3216SimBoard* board = &rig.board;
  Tmcm3216* device = &rig.device;
  can.frames.clear();
  const auto signals = sim::Tmcm3216SimBoard::signal_table();
  fuzz::SdoClientView client(*device);
  int ticks_left = 4000;  // 200 ms of motion per input at most

  // A bring-up most inputs start from, as a master does it (frames in): NMT start, a mode and
  // shutdown / switch on / enable operation on some axes; then anything.
  const uint8_t bring_up = in.ConsumeIntegral<uint8_t>();
  std::vector<can::CanFrame> prelude;
  if ((bring_up & 0x40) == 0) {
    can::CanFrame start;
    start.dlc = 2;
    start.data[0] = 0x01;
    prelude.push_back(start);
  }
  for (uint8_t axis = 0; axis < kAxes; ++axis) {
    if ((bring_up >> axis & 1) == 0) continue;
    const auto offset = static_cast<uint16_t>(axis * 0x800);
    if (bring_up & 0x80) prelude.push_back(fuzz::expedited_download(*device, static_cast<uint16_t>(0x2005 + axis * 0x200), 0, 3));
    prelude.push_back(fuzz::expedited_download(*device, 0x6060 + offset, 0, kModes[(bring_up >> 3) & 7]));
    for (uint16_t cw : {0x0006, 0x0007, 0x000F}) prelude.push_back(fuzz::expedited_download(*device, 0x6040 + offset, 0, cw));
  }
  for (const can::CanFrame& frame : prelude) {
    device->receive(frame);
    device->process(0);
  }
  can.frames.clear();

  for (int step = 0; step < 160 && in.remaining_bytes() > 0; ++step) {
    can::CanFrame frame;
    bool send = true;
    client.before(nullptr, 0);
    switch (in.ConsumeIntegralInRange<int>(0, 11)) {
      case 0:
        frame = fuzz::drive_nmt_command(in, device->node_id());
        break;
      case 1:
      case 2:
      case 3: {  // a drive object of some axis
        const uint16_t base = kDriveObjects[in.ConsumeIntegralInRange<size_t>(0, std::size(kDriveObjects) - 1)];
        const uint8_t axis = in.ConsumeIntegralInRange<uint8_t>(0, kAxes - 1);
        const uint8_t sub = base == 0x6099 || base == 0x60C2 ? in.ConsumeIntegralInRange<uint8_t>(1, 2) : 0;
        int64_t value;
        if (base == 0x6040) {
          value = kControlwords[in.ConsumeIntegralInRange<size_t>(0, std::size(kControlwords) - 1)];
        } else if (base == 0x6060) {
          value = kModes[in.ConsumeIntegralInRange<size_t>(0, std::size(kModes) - 1)];
        } else {
          value = in.ConsumeBool() ? in.ConsumeIntegralInRange<int64_t>(-200'000, 200'000) : in.ConsumeIntegral<int32_t>();
        }
        frame = fuzz::expedited_download(*device, static_cast<uint16_t>(base + axis * 0x800), sub, value);
        break;
      }
      case 4: {  // any object of the dictionary, any value (downloads) or an upload
        const auto rows = device->dictionary().rows();
        const auto& info = rows[in.ConsumeIntegralInRange<size_t>(0, rows.size() - 1)].info;
        const auto index = static_cast<uint16_t>(info.index + in.ConsumeIntegralInRange<int>(0, kAxes - 1) * info.axis_stride);
        const int64_t value = in.PickValueInArray({info.min, info.max, info.default_value, info.max + 1, info.min - 1,
                                                   static_cast<int64_t>(in.ConsumeIntegral<int32_t>())});
        frame = fuzz::expedited_download(*device, index, info.sub, value);
        if (in.ConsumeBool()) frame.data[0] = 0x40;  // initiate upload
        break;
      }
      case 5:  // an RPDO of axis 0 (defaults: 6040, 6040+6060, 6040+607A, 6040+60FF)
        frame = fuzz::drive_rpdo_frame(in, device->node_id(), kControlwords, kModes);
        break;
      case 6:  // SYNC
        frame = fuzz::sync_frame(in);
        break;
      case 7:  // any identifier
        frame = fuzz::any_frame(in);
        break;
      case 8: {  // a board input: switches, supply, temperatures, loads
        const sim::SignalInfo& signal = signals[in.ConsumeIntegralInRange<size_t>(0, signals.size() - 1)];
        double value = in.ConsumeFloatingPointInRange<double>(signal.min, signal.max);
        if (signal.whole_numbers_only) value = static_cast<double>(static_cast<int64_t>(value));
        if (sim::check_signal_value(signal, value).ok()) board->set_input(signal.name, value);
        send = false;
        break;
      }
      default: {  // motion ticks
        send = false;
        const int ticks = in.ConsumeIntegralInRange<int>(1, 1000);
        client.before(nullptr, static_cast<uint32_t>(std::min(ticks, ticks_left)) * modules::tmcm3216::kTickUs);
        run_ticks(*device, *board, ticks, ticks_left);
        break;
      }
    }

    if (send) {
      trace("->", frame);
      client.before(&frame, 0);
      device->receive(frame);
      device->process(0);
    }
    for (const can::CanFrame& out : can.frames) {
      trace("  <-", out);
      FUZZ_CHECK(out.dlc <= 8 && (out.extended ? out.id <= 0x1FFFFFFF : out.id <= 0x7FF), "frame %x with dlc %u",
                 out.id, out.dlc);
    }
    client.after(can.frames);
    can.frames.clear();
    check_statuswords(*device);
    if (step % 16 == 15) check_dictionary_ranges(*device);
  }
  check_dictionary_ranges(*device);
  if (std::getenv("MOTWIN_FUZZ_TRACE") != nullptr) {
    for (uint8_t axis = 0; axis < kAxes; ++axis) {
      std::fprintf(stderr, "axis %u: PDS state %d, mode %d, position %d\n", axis,
                   static_cast<int>(device->drive(axis).state()), device->drive(axis).mode_display(),
                   device->drive(axis).position_demand());
    }
  }
  return 0;
}
