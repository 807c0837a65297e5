// The TMCM-1636 with its CANopen firmware as host, CLI and tools know it (host/module_descriptor.h):
// the descriptor `--firmware canopen` of tmcm-1636 chooses (tmcm1636_descriptor.cpp lists it).
#include <memory>
#include <string>

#include "board/ram_non_volatile_memory.h"
#include "host/canopen_dictionary_view.h"
#include "host/module_listing.h"
#include "host/modules/tmcm1636/tmcm1636_canopen_virtual_module.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

namespace motwin::host {
namespace {

using Device = modules::tmcm1636::Tmcm1636Canopen;

// The firmware on a RAM image at factory defaults, powered up, on idle I/O: what `serve` answers
// before any write.
CanopenDictionaryView factory_dictionary() {
  auto nvm = std::make_unique<board::RamNonVolatileMemory<Device::kNvmSize>>();
  Device::format_factory_image(nvm->mutable_data(), nvm->size());
  NullCanController can;
  sim::Tmcm1636SimIo io;
  auto device = std::make_unique<Device>(*nvm, can, io);
  device->power_up();
  return view_of(device->dictionary());
}

ModuleParameterListing object_listing() { return canopen_object_listing(std::string(Device::kName), factory_dictionary()); }

const CanopenDescription kCanopen{
    .identity = {.product_name = "TMCM-1636",
                 .vendor_name = "Trinamic Motion Control GmbH",  // as the published EDS names it
                 .vendor_id = Device::kVendorId,
                 .product_code = Device::kProductCode,
                 .revision_number = Device::kRevisionNumber,
                 .rpdo_count = modules::tmcm1636::kCanopenPdoCount,
                 .tpdo_count = modules::tmcm1636::kCanopenPdoCount,
                 .bit_rates_kbit = modules::tmcm1636::kCanopenBitRatesKbit,
                 .lss_supported = Device::kNode.lss,
                 .dummy_mapping_supported = false},
    .dictionary = &factory_dictionary,
};

}  // namespace

ModuleDescriptor tmcm1636_canopen_descriptor() {
  return ModuleDescriptor{
      .name = Device::kName,
      .product_name = "TMCM-1636",
      .summary = "TMCM-1636 1-axis BLDC/DC servo module, CANopen firmware V1.12 (CiA-402 drive: pp, pv, hm, csp, csv, cst)",
      .firmware = Device::kFirmwareVersion,
      .help = R"(A CANopen node on the virtual CAN bus, no TMCL: CiA-301 (SDO, PDO, SYNC, EMCY, node guarding) and
a CiA-402 servo drive with the object dictionary of Trinamic's EDS for firmware 1.12, on the same
servo axis as the TMCL firmware (docs/tmcm-1636-canopen.md). --node-id overrides the stored node
ID (2705, default 1).)",
      .input_signals = &Tmcm1636CanopenVirtualModule::signal_table,
      .make = &Tmcm1636CanopenVirtualModule::make,
      .endpoints = {.canopen = true, .default_endpoint = DefaultEndpoint::kCanSocketcand},
      .motors = {[] { return ideal_and(sim::motor_preset_names()); },
                 R"(ideal (the axis follows the drive's demand exactly; fast, the default), a preset (a physical
model driven by the firmware's regulators; a new image gets the preset's start-up settings as
objects) or a motor description file (.json, docs/tmcm-1636-servo.md))"},
      .listing = &object_listing,
      .canopen = &kCanopen,
  };
}

}  // namespace motwin::host
