// SDO abort codes of CiA-301 (TMCM-3216 manual chapter 12, table 366). kNone (0) means success
// everywhere an abort code is returned.
#pragma once

#include <cstdint>

namespace motwin::canopen {

enum class SdoAbort : uint32_t {
  kNone = 0,
  kToggleBit = 0x0503'0000,             // toggle bit not alternated
  kTimeout = 0x0504'0000,               // SDO protocol timed out
  kUnknownCommand = 0x0504'0001,        // client/server command specifier not valid or unknown
  kInvalidBlockSize = 0x0504'0002,
  kInvalidSequence = 0x0504'0003,
  kCrc = 0x0504'0004,
  kOutOfMemory = 0x0504'0005,
  kUnsupportedAccess = 0x0601'0000,
  kWriteOnly = 0x0601'0001,             // attempt to read a write-only object
  kReadOnly = 0x0601'0002,              // attempt to write a read-only object
  kNoObject = 0x0602'0000,              // object does not exist
  kNotMappable = 0x0604'0041,
  kMappingTooLong = 0x0604'0042,
  kParameterIncompatible = 0x0604'0043,
  kDeviceIncompatible = 0x0604'0047,
  kHardware = 0x0606'0000,              // access failed due to a hardware error
  kTypeMismatch = 0x0607'0010,          // length of service parameter does not match
  kDataTooLong = 0x0607'0012,
  kDataTooShort = 0x0607'0013,
  kNoSubIndex = 0x0609'0011,
  kInvalidValue = 0x0609'0030,
  kValueTooHigh = 0x0609'0031,
  kValueTooLow = 0x0609'0032,
  kMaxLessThanMin = 0x0609'0036,
  kResourceUnavailable = 0x060A'0023,
  kGeneral = 0x0800'0000,
  kDataTransfer = 0x0800'0020,          // cannot be transferred or stored (wrong signature)
  kLocalControl = 0x0800'0021,
  kDeviceState = 0x0800'0022,           // not in the present device state
  kNoDictionary = 0x0800'0023,
  kNoData = 0x0800'0024,
};

constexpr uint32_t code(SdoAbort abort) { return static_cast<uint32_t>(abort); }

// The description of table 366 (empty for a code not in it).
constexpr const char* describe(uint32_t abort_code) {
  switch (static_cast<SdoAbort>(abort_code)) {
    case SdoAbort::kNone: return "no error";
    case SdoAbort::kToggleBit: return "toggle bit not alternated";
    case SdoAbort::kTimeout: return "SDO protocol timed out";
    case SdoAbort::kUnknownCommand: return "client/server command specifier not valid or unknown";
    case SdoAbort::kInvalidBlockSize: return "invalid block size";
    case SdoAbort::kInvalidSequence: return "invalid sequence number";
    case SdoAbort::kCrc: return "CRC error";
    case SdoAbort::kOutOfMemory: return "out of memory";
    case SdoAbort::kUnsupportedAccess: return "unsupported access to an object";
    case SdoAbort::kWriteOnly: return "attempt to read a write only object";
    case SdoAbort::kReadOnly: return "attempt to write a read only object";
    case SdoAbort::kNoObject: return "object does not exist in the object dictionary";
    case SdoAbort::kNotMappable: return "object cannot be mapped to the PDO";
    case SdoAbort::kMappingTooLong: return "the number and length of the objects to be mapped exceed the PDO length";
    case SdoAbort::kParameterIncompatible: return "general parameter incompatibility reason";
    case SdoAbort::kDeviceIncompatible: return "general internal incompatibility in the device";
    case SdoAbort::kHardware: return "access failed due to a hardware error";
    case SdoAbort::kTypeMismatch: return "data type does not match, length of service parameter does not match";
    case SdoAbort::kDataTooLong: return "data type does not match, length of service parameter too high";
    case SdoAbort::kDataTooShort: return "data type does not match, length of service parameter too low";
    case SdoAbort::kNoSubIndex: return "sub-index does not exist";
    case SdoAbort::kInvalidValue: return "invalid value for parameter";
    case SdoAbort::kValueTooHigh: return "value of parameter too high";
    case SdoAbort::kValueTooLow: return "value of parameter too low";
    case SdoAbort::kMaxLessThanMin: return "maximum value is less than minimum value";
    case SdoAbort::kResourceUnavailable: return "resource not available";
    case SdoAbort::kGeneral: return "general error";
    case SdoAbort::kDataTransfer: return "data cannot be transferred or stored to the application";
    case SdoAbort::kLocalControl: return "data cannot be transferred or stored to the application because of local control";
    case SdoAbort::kDeviceState: return "data cannot be transferred or stored to the application because of the present device state";
    case SdoAbort::kNoDictionary: return "object dictionary dynamic generation failed or no object dictionary is present";
    case SdoAbort::kNoData: return "no data available";
  }
  return "";
}

}  // namespace motwin::canopen
