// The datalogger of a TMCL module (commands 142 and 157, docs/datalogger.md) as one part the
// module holds: the sample buffer, the RAMDebug engine and its channels over the module's
// parameter tables (TmclModule::resolve_parameter_channel / read_parameter_channel). The module
// forwards command 142 to ram_debug().execute(), calls control_tick() after its axes in each
// control tick and init() at power-up (the TMCM-1636, the TMCM-3216's TMCL firmware).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/tmcl/ramdebug.h"
#include "core/tmcl/status.h"

namespace motwin::tmcl {

template <class Module, size_t kBufferWords>
class ModuleDatalogger final : public RamDebugChannels {
 public:
  ModuleDatalogger(Module& module, const RamDebugConfig& config) : module_(module), ram_debug_(*this, config, buffer_) {}
  ModuleDatalogger(const ModuleDatalogger&) = delete;
  ModuleDatalogger& operator=(const ModuleDatalogger&) = delete;

  RamDebug& ram_debug() { return ram_debug_; }
  void control_tick() { ram_debug_.control_tick(); }
  void init() { ram_debug_.init(); }

  // RamDebugChannels: axis and global parameters through the module's tables.
  Status resolve_ram_debug_channel(uint8_t type, uint32_t select, RamDebugProbe& probe) override {
    return module_.resolve_parameter_channel(type, select, probe);
  }
  int32_t read_ram_debug_channel(const RamDebugProbe& probe) override { return module_.read_parameter_channel(probe); }

 private:
  Module& module_;
  std::array<uint32_t, kBufferWords> buffer_{};
  RamDebug ram_debug_;
};

}  // namespace motwin::tmcl
