// What the firmware-change tests of the modules with a TMCL and a CANopen firmware share
// (docs/host-runtime.md "Changing firmware"): each firmware's virtual module made on a state
// directory with its log caught, GAP / SAP + STAP on the TMCL one, dictionary reads, writes and
// 1010 stores on the CANopen one, and the checks of a change (one line, nothing set aside).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/canopen/node.h"
#include "core/canopen/object_dictionary.h"
#include "core/tmcl/status.h"
#include "host/eeprom_file.h"
#include "host/module_descriptor.h"
#include "host/virtual_module.h"
#include "host_test_support.h"

namespace motwin::testing {

inline host::ModuleOptions options_in(const std::filesystem::path& dir, std::vector<std::string>& log,
                                      std::string firmware = "") {
  host::ModuleOptions options;
  options.state_dir = dir;
  options.firmware = std::move(firmware);
  options.log = [&log](const std::string& line) { log.push_back(line); };
  return options;
}

// The CANopen firmware's virtual module `VirtualModuleT`.
template <class VirtualModuleT>
struct CanopenOn {
  std::unique_ptr<host::VirtualModule> module;

  auto& device() { return static_cast<VirtualModuleT&>(*module).device(); }
  int64_t read(uint16_t index, uint8_t sub = 0) {
    canopen::ObjectRef ref;
    EXPECT_EQ(device().dictionary().find(index, sub, ref), canopen::SdoAbort::kNone) << std::hex << index;
    return device().dictionary().value(ref);
  }
  // As an SDO download: every check of the object.
  void write(uint16_t index, uint8_t sub, int64_t value) {
    canopen::ObjectRef ref;
    ASSERT_EQ(device().dictionary().find(index, sub, ref), canopen::SdoAbort::kNone) << std::hex << index;
    uint8_t bytes[8] = {};
    canopen::encode_value(ref.info->type, value, bytes);
    ASSERT_EQ(device().dictionary().write(ref, bytes, canopen::type_size(ref.info->type)), canopen::SdoAbort::kNone)
        << std::hex << index << " sub " << int{sub};
  }
  // 1010 sub `sub` with the save signature.
  void store(uint8_t sub) {
    ASSERT_EQ(device().node().store_parameters(sub, canopen::kSaveSignature), canopen::SdoAbort::kNone);
  }
};

// The TMCL firmware's virtual module `VirtualModuleT`.
template <class VirtualModuleT>
struct TmclOn {
  std::unique_ptr<host::VirtualModule> module;

  auto& device() { return static_cast<VirtualModuleT&>(*module).device(); }
  int32_t gap(uint8_t number, uint8_t motor = 0) {
    int32_t value = 0;
    EXPECT_EQ(device().get_axis_parameter(number, motor, value), tmcl::Status::kOk) << "AP " << int{number};
    return value;
  }
  void sap_stap(uint8_t number, uint8_t motor, int32_t value) {
    ASSERT_EQ(device().set_axis_parameter(number, motor, value), tmcl::Status::kOk) << "AP " << int{number};
    ASSERT_EQ(device().store_axis_parameter(number, motor), tmcl::Status::kOk) << "AP " << int{number};
  }
};

// `Opened` (a CanopenOn or TmclOn) on `dir` with `make` (a virtual module's make()).
template <class Opened>
Opened open_on(host::MakeModuleResult (*make)(const host::ModuleOptions&), const std::filesystem::path& dir,
               std::vector<std::string>& log, std::string firmware = "") {
  host::MakeModuleResult made = make(options_in(dir, log, std::move(firmware)));
  EXPECT_TRUE(made) << (made ? "" : made.error());
  return Opened{made ? std::move(*made) : nullptr};
}

inline size_t lines_with(const std::vector<std::string>& log, const std::string& text) {
  size_t count = 0;
  for (const std::string& line : log) count += line.find(text) != std::string::npos ? 1 : 0;
  return count;
}

inline bool damaged_exists(const ScratchDirectory& dir, std::string_view module_name) {
  return std::filesystem::exists(host::EepromFile::image_path(dir.path(), module_name).string() + ".damaged");
}

// The one line of a change, and nothing set aside.
inline void expect_taken_over(const std::vector<std::string>& log, const std::string& line, const ScratchDirectory& dir,
                              std::string_view module_name) {
  EXPECT_EQ(log.size(), 1u);
  EXPECT_EQ(lines_with(log, line), 1u) << (log.empty() ? "" : log[0]);
  EXPECT_FALSE(damaged_exists(dir, module_name));
}

// An AP of a motor, or a CANopen object, with a value.
struct ApValue {
  uint8_t number;
  uint8_t motor;
  int64_t value;
};
struct ObjectValue {
  uint16_t index;
  uint8_t sub;
  int64_t value;
};

template <class Tmcl>
void expect_aps(Tmcl& tmcl, std::initializer_list<ApValue> expected) {
  for (const ApValue& e : expected) {
    EXPECT_EQ(tmcl.gap(e.number, e.motor), e.value) << "AP " << int{e.number} << " of motor " << int{e.motor};
  }
}

template <class Canopen>
void expect_objects(Canopen& canopen, std::initializer_list<ObjectValue> expected) {
  for (const ObjectValue& e : expected) {
    EXPECT_EQ(canopen.read(e.index, e.sub), e.value) << std::hex << e.index << " sub " << int{e.sub};
  }
}

template <class Canopen>
void write_objects(Canopen& canopen, std::initializer_list<ObjectValue> writes) {
  for (const ObjectValue& w : writes) canopen.write(w.index, w.sub, w.value);
}

template <class Tmcl>
void sap_stap_all(Tmcl& tmcl, std::initializer_list<ApValue> settings) {
  for (const ApValue& s : settings) tmcl.sap_stap(s.number, s.motor, static_cast<int32_t>(s.value));
}

}  // namespace motwin::testing
