// A setting that two firmwares of one module share: a TMCL axis parameter and the CANopen object
// of the same meaning. A module whose firmwares speak TMCL and CANopen lists them in one table
// (the TMCM-3216's: core/modules/tmcm3216/tmcm3216_firmware_change.h) that a firmware change on
// one EEPROM image reads (docs/host-runtime.md "Changing firmware"): the previous firmware's value
// is read through its own interface and written through the new firmware's, with the conversion
// the row names. Plain data: the host layer drives the conversion.
#pragma once

#include <cstdint>

namespace motwin::params {

// How a value in the CANopen object relates to the TMCL parameter's.
enum class SharedConversion : uint8_t {
  kSame,          // the same number in both
  kVelocity,      // TMCL in pps; CANopen in the velocity unit its axis is set to (e.g. 208C)
  kAcceleration,  // TMCL in pps/s; CANopen in the acceleration unit of its axis (e.g. 208E)
  kBit,           // TMCL 0/1; CANopen one bit (`bit_mask`) of the object, its other bits kept
};

struct SharedAxisSetting {
  uint8_t parameter;     // TMCL axis parameter (per motor)
  uint16_t index;        // CANopen object of axis 0
  uint8_t sub;           // its sub-index
  uint16_t axis_stride;  // axis n's object is at index + n * axis_stride
  SharedConversion conversion = SharedConversion::kSame;
  uint32_t bit_mask = 0;  // kBit only

  constexpr uint16_t index_of(uint8_t axis) const { return static_cast<uint16_t>(index + axis * axis_stride); }
};

// One row each, so that a row of a module's table is one line.
constexpr SharedAxisSetting same(uint8_t parameter, uint16_t index, uint16_t axis_stride, uint8_t sub = 0) {
  return {parameter, index, sub, axis_stride, SharedConversion::kSame, 0};
}
constexpr SharedAxisSetting velocity(uint8_t parameter, uint16_t index, uint16_t axis_stride, uint8_t sub = 0) {
  return {parameter, index, sub, axis_stride, SharedConversion::kVelocity, 0};
}
constexpr SharedAxisSetting acceleration(uint8_t parameter, uint16_t index, uint16_t axis_stride, uint8_t sub = 0) {
  return {parameter, index, sub, axis_stride, SharedConversion::kAcceleration, 0};
}
constexpr SharedAxisSetting bit(uint8_t parameter, uint16_t index, uint16_t axis_stride, uint32_t mask,
                                uint8_t sub = 0) {
  return {parameter, index, sub, axis_stride, SharedConversion::kBit, mask};
}

}  // namespace motwin::params
