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

}  // namespace motwin::canopen
