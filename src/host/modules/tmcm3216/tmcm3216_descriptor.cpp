// The TMCM-3216 as host, CLI and tools know it (host/module_descriptor.h).
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "board/can_controller.h"
#include "board/ram_non_volatile_memory.h"
#include "host/canopen_dictionary_view.h"
#include "host/module_listing.h"
#include "host/modules/tmcm3216/tmcm3216_tmcl_virtual_module.h"
#include "host/modules/tmcm3216/tmcm3216_virtual_module.h"
#include "sim/stepper_motor_selection.h"

namespace motwin::host {
namespace {

using Device = modules::tmcm3216::Tmcm3216;

// The firmware on a RAM image at factory defaults, powered up: the visible strings and the
// table come from the real profile, as `serve` would answer them before any write.
CanopenDictionaryView factory_dictionary() {
  auto nvm = std::make_unique<board::RamNonVolatileMemory<Device::kNvmSize>>();
  Device::format_factory_image(nvm->mutable_data(), nvm->size());
  NullCanController can;
  auto device = std::make_unique<Device>(*nvm, can);
  device->power_up();
  return view_of(device->dictionary());
}

ModuleParameterListing object_listing() { return canopen_object_listing(std::string(Device::kName), factory_dictionary()); }

// Manual table 177: 20, 50, 100, 125, 250, 500, 800 and 1000 kbit/s.
constexpr uint16_t kBitRatesKbit[] = {20, 50, 100, 125, 250, 500, 800, 1000};
constexpr uint8_t kPdos = modules::tmcm3216::kAxisCount * modules::tmcm3216::kPdosPerAxis;

const CanopenDescription kCanopen{
    .identity = {.product_name = "TMCM-3216",
                 .vendor_name = "Trinamic Motion Control (Analog Devices)",
                 .vendor_id = Device::kVendorId,
                 .product_code = Device::kProductCode,
                 .revision_number = Device::kRevisionNumber,
                 .rpdo_count = kPdos,
                 .tpdo_count = kPdos,
                 .bit_rates_kbit = kBitRatesKbit,
                 .lss_supported = true,  // core/canopen/lss_slave.h
                 .dummy_mapping_supported = true},
    .dictionary = &factory_dictionary,
};

}  // namespace

ModuleDescriptor tmcm3216_descriptor() {
  return ModuleDescriptor{
      .name = Device::kName,
      .product_name = "TMCM-3216",
      .summary = "TMCM-3216 3-axis stepper module, CANopen firmware V1.04 (CiA-402 drive: pp, pv, hm, csp, csv; TMCL: --firmware tmcl)",
      .firmware = Device::kFirmwareVersion,
      .help = R"(A CANopen node on the virtual CAN bus, no TMCL: CiA-301 (SDO, PDO, SYNC, EMCY, LSS) and a
CiA-402 drive per axis (docs/canopen.md, docs/tmcm-3216-drive.md). --node-id overrides the
stored node ID (2705, default 1); the node leaves a bus whose bit rate differs from its active
one (2704 at reset, or set by LSS).)",
      .input_signals = &Tmcm3216VirtualModule::signal_table,
      .make = &Tmcm3216VirtualModule::make,
      .endpoints = {.canopen = true, .default_endpoint = DefaultEndpoint::kCanSocketcand},
      .motors = {[] { return ideal_and(sim::stepper_motor_preset_names()); },
                 R"(ideal (the rotor follows the field exactly, the default), a preset stepper or a stepper
description file (.json, docs/tmcm-142.md, "Motor") for all three axes, or a comma-separated
list, one per axis, e.g. nema17,ideal,nema23 (docs/tmcm-3216-drive.md))"},
      .listing = &object_listing,
      .canopen = &kCanopen,
      .firmwares = {{.name = "canopen",
                     .version = Device::kFirmwareVersion,
                     .help = "the CANopen firmware V1.04 (CiA-301/402, the default)",
                     .listing = &object_listing},
                    {.name = "tmcl",
                     .version = modules::tmcm3216::kTmclFacts.identity.version_string,
                     .help = "the TMCL firmware (PyTrinamic's TMCM3216 class, Zephyr's driver): three TMCL axes, no CANopen",
                     .descriptor = &tmcm3216_tmcl_descriptor}},
  };
}

}  // namespace motwin::host
