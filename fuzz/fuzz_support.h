// Shared by the libFuzzer targets in this folder: the invariant check and small module rigs
// (a TMCM-1636 and a TMCM-3216 on RAM EEPROMs). Each input gets a fresh rig (fresh_rig(): a rig
// constructed in the same static memory for every input), so an input replays the same way under
// `scripts/fuzz.sh` and when a crash file is run again.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <vector>

#include "board/can_controller.h"
#include "board/ram_non_volatile_memory.h"
#include "board/modules/tmcm1636/tmcm1636_io.h"
#include "core/modules/tmcm1636/tmcm1636.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "core/tmcl/engine.h"
#include "types/can_frame.h"

// An invariant violation is a crash for libFuzzer: it saves the input as crash-<sha1>.
#define FUZZ_CHECK(condition, ...)                                                                  \
  do {                                                                                              \
    if (!(condition)) {                                                                             \
      std::fprintf(stderr, "\ninvariant violated at %s:%d: %s\n  ", __FILE__, __LINE__, #condition); \
      std::fprintf(stderr, __VA_ARGS__);                                                            \
      std::fputc('\n', stderr);                                                                     \
      std::abort();                                                                                 \
    }                                                                                               \
  } while (0)

// For the range checks that run after every instruction or tick batch: their own branches and
// comparisons are left out of libFuzzer's coverage and comparison tracing (a third of the engine
// targets' time, and no guidance: the values compared come from the module, the functions they
// call stay instrumented). fuzz/README.md, Decisions.
#define FUZZ_UNTRACED __attribute__((no_sanitize("coverage")))

namespace motwin::fuzz {

// Fixed inputs: 24 V supply, 25 °C, switches open. The fuzzed bytes are the only variable.
class FixedTmcm1636Io final : public board::Tmcm1636Io {
 public:
  bool digital_input(uint8_t) const override { return false; }
  uint16_t analog_input(uint8_t channel) const override { return kAnalog[channel % kAnalog.size()]; }
  void set_digital_output(uint8_t port, bool on) override { outputs_[port % outputs_.size()] = on; }
  bool digital_output(uint8_t port) const override { return outputs_[port % outputs_.size()]; }
  bool reference_switch_level(board::ReferenceSwitch) const override { return false; }

 private:
  static constexpr std::array<uint16_t, 4> kAnalog{0, 0, 745, 14894};
  std::array<bool, 16> outputs_{};
};

// A module's factory EEPROM image, formatted once per process (the same bytes every time).
template <typename Module, size_t kSize>
const std::array<uint8_t, kSize>& factory_image() {
  static const std::array<uint8_t, kSize> image = [] {
    std::array<uint8_t, kSize> bytes{};
    Module::format_factory_image(bytes.data(), bytes.size());
    return bytes;
  }();
  return image;
}

// Each input's rig is a freshly constructed one, but built in the same memory every time: a rig is
// constructed in a static buffer at the start of an input and destroyed at its end (when the
// returned handle goes), so an input allocates and frees on the heap only what the modules do, as
// before, and libFuzzer's per-input leak detection stays balanced. A heap allocation of the rig per
// input cost more than its construction (AddressSanitizer hands out fresh, page-faulting memory
// each time); only the modules' public constructors and power-up are used, so the rig stays what
// `new Rig` gives. `Rig::state()` is what the rigs are compared by: on the first input and then
// every 2^16th, the rig built in place must equal one built on the heap. A target that needs two
// rigs at once gives the second another `kSlot`.
constexpr uint64_t kRigComparisonPeriod = 1 << 16;

template <typename Rig>
struct DestroyInPlace {
  bool* in_use;
  void operator()(Rig* rig) const {
    std::destroy_at(rig);
    *in_use = false;
  }
};
template <typename Rig>
using RigHandle = std::unique_ptr<Rig, DestroyInPlace<Rig>>;

template <typename Rig, int kSlot = 0>
RigHandle<Rig> fresh_rig() {
  alignas(Rig) static std::byte storage[sizeof(Rig)];
  static bool in_use = false;
  static uint64_t inputs = 0;
  FUZZ_CHECK(!in_use, "fresh_rig: the slot's previous rig is still in use");
  in_use = true;
  RigHandle<Rig> rig(std::construct_at(reinterpret_cast<Rig*>(storage)), DestroyInPlace<Rig>{&in_use});
  if (inputs++ % kRigComparisonPeriod == 0) {
    const auto built_on_heap = std::make_unique<Rig>();
    FUZZ_CHECK(rig->state() == built_on_heap->state(), "a rig built in place differs from one built on the heap");
  }
  return rig;
}

using Tmcm1636 = modules::tmcm1636::Tmcm1636;
using Tmcm1636Nvm = board::RamNonVolatileMemory<Tmcm1636::kNvmLayout.total_size>;

// Every readable parameter of bank 0 and every axis parameter of every motor, as GAP/GGP see
// them, plus banks 1..3 (user variables and the module's banks).
template <typename Module>
std::vector<int32_t> probe_parameters(Module& module) {
  std::vector<int32_t> values;
  for (uint8_t motor = 0; motor < Module::kMotorCount; ++motor) {
    for (const auto& row : module.axis_table().rows()) {
      int32_t value = 0;
      const auto status = module.get_axis_parameter(static_cast<uint8_t>(row.info.number), motor, value);
      values.push_back(static_cast<int32_t>(status) * 7919 + value);
    }
  }
  for (const auto& row : Module::global_parameters().rows()) {
    int32_t value = 0;
    const auto status = module.get_global_parameter(static_cast<uint8_t>(row.info.number), 0, value);
    values.push_back(static_cast<int32_t>(status) * 7919 + value);
  }
  for (int bank = 1; bank <= 3; ++bank) {
    for (int number = 0; number < 256; ++number) {
      int32_t value = 0;
      const auto status = module.get_global_parameter(static_cast<uint8_t>(number), static_cast<uint8_t>(bank), value);
      values.push_back(static_cast<int32_t>(status) * 7919 + value);
    }
  }
  return values;
}

// The parameters and the EEPROM image: what a fresh rig is compared by.
template <typename Module, typename Nvm>
std::vector<int32_t> module_state(Module& module, const Nvm& nvm) {
  std::vector<int32_t> values = probe_parameters(module);
  values.insert(values.end(), nvm.data(), nvm.data() + nvm.size());
  return values;
}

// A TMCM-1636 on a RAM EEPROM with the factory image, powered up (fresh_rig<Tmcm1636Rig>()).
struct Tmcm1636Rig {
  Tmcm1636Nvm nvm;
  FixedTmcm1636Io io;
  Tmcm1636 module{nvm, io};
  tmcl::TmclEngine& engine{module.engine()};

  Tmcm1636Rig() {
    const auto& image = factory_image<Tmcm1636, Tmcm1636::kNvmLayout.total_size>();
    std::memcpy(nvm.mutable_data(), image.data(), image.size());
    engine.power_up();
  }
  std::vector<int32_t> state() { return module_state(module, nvm); }
};

// A writable axis parameter (of every motor) holds a value inside its row's range, whatever came before.
// The rows' getters are called directly, as get_axis_parameter() does after finding the row (a
// search per parameter cost about half of each input's time).
template <typename Module>
FUZZ_UNTRACED void check_axis_parameter_ranges(Module& module, const char* when) {
  for (const auto& row : module.axis_table().rows()) {
    if (!params::has(row.info.access, params::Access::kWrite) || !params::has(row.info.access, params::Access::kRead) ||
        row.binding.get == nullptr) {
      continue;
    }
    for (uint8_t motor = 0; motor < Module::kMotorCount; ++motor) {
      const int32_t value = row.binding.get(module, motor);
      FUZZ_CHECK(params::in_range(row.info, value), "%s: AP %u (%.*s) of motor %u holds %d, range %lld..%lld", when,
                 row.info.number, static_cast<int>(row.info.name.size()), row.info.name.data(), motor, value,
                 static_cast<long long>(row.info.min), static_cast<long long>(row.info.max));
    }
  }
}

// The same for the writable global parameters of bank 0.
template <typename Module>
FUZZ_UNTRACED void check_global_parameter_ranges(Module& module, const char* when) {
  for (const auto& row : Module::global_parameters().rows()) {
    if (!params::has(row.info.access, params::Access::kWrite) || !params::has(row.info.access, params::Access::kRead) ||
        row.binding.get == nullptr) {
      continue;
    }
    const int32_t value = row.binding.get(module, 0);  // bank 0
    FUZZ_CHECK(params::in_range(row.info, value), "%s: GP %u (%.*s) holds %d, range %lld..%lld", when,
               row.info.number, static_cast<int>(row.info.name.size()), row.info.name.data(), value,
               static_cast<long long>(row.info.min), static_cast<long long>(row.info.max));
  }
}

// A TMCL module (TMCM-1636, TMCM-142, TMCM-3216 TMCL): every writable parameter within its range.
template <typename Module>
void check_parameter_ranges(Module& module, const char* when) {
  check_axis_parameter_ranges(module, when);
  check_global_parameter_ranges(module, when);
}

// Keeps what the module sends; the fuzz targets inspect it after each process() call.
class RecordingCan final : public board::CanController {
 public:
  std::vector<can::CanFrame> frames;
  bool transmit(const can::CanFrame& frame) override {
    if (frames.size() < 4096) frames.push_back(frame);
    return true;
  }
};

using Tmcm3216 = modules::tmcm3216::Tmcm3216;
using Tmcm3216Nvm = board::RamNonVolatileMemory<Tmcm3216::kNvmSize>;

// Every readable numeric object of every axis (its SDO abort where it has none) and the EEPROM
// image: what a fresh rig of a CANopen module (the TMCM-3216, the TMCM-1636's CANopen firmware) is
// compared by.
template <class Device, class Nvm>
std::vector<int64_t> dictionary_state(Device& device, const Nvm& nvm) {
  std::vector<int64_t> values;
  auto& dictionary = device.dictionary();
  const auto rows = dictionary.rows();
  for (size_t row = 0; row < rows.size(); ++row) {
    const canopen::EntryInfo& info = rows[row].info;
    const uint8_t axes = info.axis_stride == 0 ? 1 : dictionary.axis_count();
    for (uint8_t axis = 0; axis < axes; ++axis) {
      const canopen::ObjectRef ref{&info, row, static_cast<uint16_t>(info.index + axis * info.axis_stride), axis};
      uint8_t bytes[64] = {};
      size_t length = 0;
      const canopen::SdoAbort abort = dictionary.read(ref, bytes, sizeof(bytes), length);
      values.push_back(static_cast<int64_t>(abort));
      for (size_t i = 0; i < length; ++i) values.push_back(bytes[i]);
    }
  }
  values.push_back(device.node_id());
  values.push_back(static_cast<int64_t>(device.nmt_state()));
  values.push_back(device.node().restarting());
  values.insert(values.end(), nvm.data(), nvm.data() + nvm.size());
  return values;
}

// A TMCM-3216 (communication only: the board of its own) on a RAM EEPROM with the factory image,
// powered up (fresh_rig<Tmcm3216Rig>()).
struct Tmcm3216Rig {
  Tmcm3216Nvm nvm_storage;
  // The image is in place before the module is constructed (members initialise in this order).
  struct FactoryImage {
    explicit FactoryImage(Tmcm3216Nvm& memory) {
      const auto& image = factory_image<Tmcm3216, Tmcm3216::kNvmSize>();
      std::memcpy(memory.mutable_data(), image.data(), image.size());
    }
  } factory_image_copied{nvm_storage};
  Tmcm3216Nvm* nvm = &nvm_storage;
  RecordingCan can;
  Tmcm3216 device_storage{nvm_storage, can};
  Tmcm3216* device = &device_storage;

  Tmcm3216Rig() { device->power_up(); }
  std::vector<int64_t> state() { return dictionary_state(*device, *nvm); }
};

}  // namespace motwin::fuzz
