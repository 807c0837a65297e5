// A firmware change between protocols on one EEPROM image (docs/host-runtime.md "Changing
// firmware"): the settings two firmwares of a module share (its params::SharedAxisSetting table)
// read from the previous firmware through its own interface (TMCL GAP, or the CANopen dictionary)
// and written through the new one's (SAP and STAP per motor, or dictionary writes that the module
// then stores with 1010). Each firmware runs on a copy of an image in memory; the module's
// take-over (EepromImageIdentity::take_over_firmware) powers them up and hands the new image on.
// A value the new firmware refuses (range, checks) leaves its default.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "board/ram_non_volatile_memory.h"
#include "core/canopen/object_dictionary.h"
#include "core/cia402/profile_objects.h"
#include "core/params/shared_setting.h"
#include "core/tmcl/device.h"

namespace motwin::host {

// The value of each shared setting of each axis in the TMCL parameter's units (pps, pps/s, 0/1);
// empty where the previous firmware could not give one.
class SharedSettingValues {
 public:
  SharedSettingValues(std::span<const params::SharedAxisSetting> rows, uint8_t axis_count)
      : rows_(rows), axis_count_(axis_count), values_(rows.size() * axis_count) {}

  std::span<const params::SharedAxisSetting> rows() const { return rows_; }
  uint8_t axis_count() const { return axis_count_; }
  std::optional<int64_t>& at(size_t row, uint8_t axis) { return values_[row * axis_count_ + axis]; }
  const std::optional<int64_t>& at(size_t row, uint8_t axis) const { return values_[row * axis_count_ + axis]; }

 private:
  std::span<const params::SharedAxisSetting> rows_;
  uint8_t axis_count_;
  std::vector<std::optional<int64_t>> values_;
};

// A firmware powered up on a copy of an image in memory (kSize bytes): `Device` made by
// `make(nvm, peripherals)` on default-constructed `Peripherals` (the board seams, a CAN controller
// that sends nowhere), then power_up(), so that it holds what the image stores.
template <class Device, size_t kSize, class Peripherals>
struct FirmwareOnImage {
  template <class Make>
  FirmwareOnImage(const uint8_t* bytes, const Make& make)
      : nvm(std::make_unique<board::RamNonVolatileMemory<kSize>>()), peripherals(std::make_unique<Peripherals>()) {
    std::memcpy(nvm->mutable_data(), bytes, kSize);
    device = make(*nvm, *peripherals);
    device->power_up();
  }
  // The image as the firmware left it.
  void copy_image(uint8_t* out) const { std::memcpy(out, nvm->data(), kSize); }

  std::unique_ptr<board::RamNonVolatileMemory<kSize>> nvm;
  std::unique_ptr<Peripherals> peripherals;
  std::unique_ptr<Device> device;
};

// The units of a CANopen axis' velocity and acceleration objects (the TMCM-3216: 208C).
using CanopenAxisUnits = std::function<cia402::UnitScale(uint8_t axis)>;

// GAP of every row and motor.
SharedSettingValues read_tmcl_settings(tmcl::TmclDevice& device, std::span<const params::SharedAxisSetting> rows,
                                       uint8_t motor_count);
// SAP, then STAP, of every value; a value SAP refuses keeps the default. The number written and stored.
size_t write_tmcl_settings(tmcl::TmclDevice& device, const SharedSettingValues& values);

// Every row's object of every axis, converted to the TMCL units.
SharedSettingValues read_canopen_settings(canopen::ObjectDictionary& dictionary,
                                          std::span<const params::SharedAxisSetting> rows, uint8_t axis_count,
                                          const CanopenAxisUnits& units);
// Every value converted to the object's units and written as an SDO download would (range and the
// object's checks; a refused value keeps the default). The number written; the caller stores them.
size_t write_canopen_settings(canopen::ObjectDictionary& dictionary, const SharedSettingValues& values,
                              const CanopenAxisUnits& units);

}  // namespace motwin::host
