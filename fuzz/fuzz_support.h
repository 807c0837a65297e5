// Shared by the libFuzzer targets in this folder: the invariant check and small module rigs
// (a TMCM-1636 and a TMCM-3216 on RAM EEPROMs). Each target builds a fresh module per input, so
// an input replays the same way under `scripts/fuzz.sh` and when a crash file is run again.
#pragma once

#include <array>
#include <cstdio>
#include <cstdlib>
#include <memory>
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

using Tmcm1636 = modules::tmcm1636::Tmcm1636;
using Tmcm1636Nvm = board::RamNonVolatileMemory<Tmcm1636::kNvmLayout.total_size>;

// Heap-allocated once per input: the module with its program memory is a few KiB.
struct Tmcm1636Rig {
  Tmcm1636Nvm nvm;
  FixedTmcm1636Io io;
  Tmcm1636 module{nvm, io};
  tmcl::TmclEngine& engine{module.engine()};

  Tmcm1636Rig() {
    Tmcm1636::format_factory_image(nvm.mutable_data(), nvm.size());
    engine.power_up();
  }
};

// Every readable parameter of bank 0 and every axis parameter, as GAP/GGP see them.
inline std::vector<int32_t> probe_parameters(Tmcm1636& module) {
  std::vector<int32_t> values;
  for (const auto& row : Tmcm1636::axis_parameters().rows()) {
    int32_t value = 0;
    const auto status = module.get_axis_parameter(static_cast<uint8_t>(row.info.number), 0, value);
    values.push_back(static_cast<int32_t>(status) * 7919 + value);
  }
  for (const auto& row : Tmcm1636::global_parameters().rows()) {
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

// A writable axis parameter (motor 0) holds a value inside its row's range, whatever came before.
template <typename Module>
void check_axis_parameter_ranges(Module& module, const char* when) {
  for (const auto& row : Module::axis_parameters().rows()) {
    if (!params::has(row.info.access, params::Access::kWrite) || !params::has(row.info.access, params::Access::kRead)) {
      continue;
    }
    int32_t value = 0;
    if (module.get_axis_parameter(static_cast<uint8_t>(row.info.number), 0, value) != tmcl::Status::kOk) continue;
    FUZZ_CHECK(params::in_range(row.info, value), "%s: AP %u (%.*s) holds %d, range %lld..%lld", when,
               row.info.number, static_cast<int>(row.info.name.size()), row.info.name.data(), value,
               static_cast<long long>(row.info.min), static_cast<long long>(row.info.max));
  }
}

// The same for the writable global parameters of bank 0.
template <typename Module>
void check_global_parameter_ranges(Module& module, const char* when) {
  for (const auto& row : Module::global_parameters().rows()) {
    if (!params::has(row.info.access, params::Access::kWrite) || !params::has(row.info.access, params::Access::kRead)) {
      continue;
    }
    int32_t value = 0;
    if (module.get_global_parameter(static_cast<uint8_t>(row.info.number), 0, value) != tmcl::Status::kOk) continue;
    FUZZ_CHECK(params::in_range(row.info, value), "%s: GP %u (%.*s) holds %d, range %lld..%lld", when,
               row.info.number, static_cast<int>(row.info.name.size()), row.info.name.data(), value,
               static_cast<long long>(row.info.min), static_cast<long long>(row.info.max));
  }
}

// A TMCL module (TMCM-1636, TMCM-142): every writable parameter within its range.
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

struct Tmcm3216Rig {
  std::unique_ptr<Tmcm3216Nvm> nvm = std::make_unique<Tmcm3216Nvm>();
  RecordingCan can;
  std::unique_ptr<Tmcm3216> device;

  Tmcm3216Rig() {
    Tmcm3216::format_factory_image(nvm->mutable_data(), nvm->size());
    device = std::make_unique<Tmcm3216>(*nvm, can);
    device->power_up();
  }
};

}  // namespace motwin::fuzz
