// PDO mapping and RPDO payloads on the TMCM-3216 (src/core/canopen/pdo.*): SDO writes that
// (re)configure PDO communication and mapping parameters (1400.., 1600.., 1800.., 1A00.., also
// as a whole remapping in the order CiA-301 asks for), frames on the RPDOs' identifiers with any
// length and payload, SYNC, NMT and time.
//
// Invariants:
// - an RPDO never puts a value outside its range into the object dictionary (every writable
//   numeric object of every axis stays inside its row's range), whatever its payload;
// - every SDO answer is the one the client expects (fuzz::SdoClientView, canopen_checks.h): one
//   response per request, index echoed, CiA-301 abort codes; a write acknowledged without abort
//   reads back as written (a mapping entry, a COB-ID), an aborted one changes nothing;
// - every frame the device sends is a classic data frame of at most 8 bytes; EMCY frames have 8
//   (a frame on the EMCY's identifier that a valid TPDO also has is that TPDO's).
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "canopen_checks.h"

namespace {

using namespace motwin;

bool is_pdo_parameter(uint16_t index) { return index >= 0x1400 && index <= 0x1BFF; }

struct Target {
  uint16_t index;
  uint8_t sub;
};

class PdoFuzzer {
 public:
  PdoFuzzer(FuzzedDataProvider& in, fuzz::Tmcm3216Rig& rig)
      : in_(in), rig_(rig), device_(*rig.device), tables_(Tables::of(device_)) {}

  void run() {
    for (int step = 0; step < 160 && in_.remaining_bytes() > 0; ++step) {
      switch (in_.ConsumeIntegralInRange<int>(0, 9)) {
        case 0: nmt(); break;
        case 1: remap(); break;
        case 2: case 3: write_parameter(); break;
        case 4: sync(); break;
        case 5: elapse(in_.ConsumeIntegralInRange<uint32_t>(0, 200'000)); break;
        default: rpdo_frame(); break;
      }
      if (step % 4 == 3) fuzz::check_dictionary_ranges(device_);
    }
    fuzz::check_dictionary_ranges(device_);
  }

 private:
  uint32_t mapping_entry() {
    if (!mappable_.empty() && in_.ConsumeIntegralInRange<int>(0, 4) != 0) {
      return mappable_[in_.ConsumeIntegralInRange<size_t>(0, mappable_.size() - 1)];
    }
    return in_.ConsumeBool() ? (0x0005u + in_.ConsumeIntegralInRange<uint32_t>(0, 2)) << 16 | 8u  // dummies
                             : in_.ConsumeIntegral<uint32_t>();
  }

  // A PDO communication parameter (numeric, readable) through the checks' untraced lookup.
  uint32_t read_u32(uint16_t index, uint8_t sub) {
    canopen::ObjectRef ref;
    if (!fuzz::ObjectLookup::of(device_).find(index, sub, ref) || !canopen::readable(ref.info->access) ||
        !canopen::is_numeric(ref.info->type)) {
      return 0;
    }
    uint8_t bytes[8] = {};
    fuzz::read_numeric(device_, ref, bytes);
    return fuzz::le32(bytes);
  }

  // An expedited SDO download through the bus, as a master does it; returns the abort code.
  uint32_t sdo_write(uint16_t index, uint8_t sub, uint32_t value, uint8_t size) {
    const can::CanFrame request = fuzz::expedited_download(device_.node_id(), index, sub, value, size);
    uint32_t abort = 0;
    deliver(request, [&](const can::CanFrame& response) {
      if (response.data[0] == 0x80) abort = fuzz::le32(&response.data[4]);
    });
    return abort;
  }

  template <class OnSdoResponse>
  void deliver(const can::CanFrame& frame, OnSdoResponse on_sdo_response) {
    const uint8_t node = device_.node_id();
    fuzz::trace("->", frame);
    client_.before(&frame, 0);
    device_.receive(frame);
    device_.process(0);
    check_output(node, on_sdo_response);
  }

  void elapse(uint32_t elapsed_us) {
    const uint8_t node = device_.node_id();
    client_.before(nullptr, elapsed_us);
    device_.process(elapsed_us);
    check_output(node, [](const can::CanFrame&) {});
  }

  // CiA-301 restricts neither 81h..FFh for a PDO: a TPDO given the EMCY's identifier sends its
  // frames there, and they are no EMCYs (campaign finding of 2026-11-27, fuzz/README.md).
  bool is_tpdo_identifier(uint32_t id) {
    for (const uint16_t axis_offset : {0x00, 0x40, 0x80}) {
      for (uint16_t number = 0; number < 4; ++number) {
        const uint32_t cob_id = read_u32(static_cast<uint16_t>(0x1800 + number + axis_offset), 1);
        if ((cob_id & canopen::kPdoCobIdInvalid) == 0 && (cob_id & 0x1FFF'FFFF) == id) return true;
      }
    }
    return false;
  }

  template <class OnSdoResponse>
  void check_output(uint8_t node, OnSdoResponse on_sdo_response) {
    for (const can::CanFrame& out : rig_.can.frames) {
      fuzz::trace("  <-", out);
      FUZZ_CHECK(out.dlc <= 8 && !out.rtr && out.id <= can::kMaxStandardId, "frame %x dlc %u", out.id, out.dlc);
      if (out.id == 0x80u + node && !is_tpdo_identifier(out.id)) FUZZ_CHECK(out.dlc == 8, "EMCY with %u bytes", out.dlc);
      if (out.id == canopen::kSdoResponseCobIdBase + node) on_sdo_response(out);
    }
    client_.after(rig_.can.frames);
    rig_.can.frames.clear();
  }

  void nmt() {
    can::CanFrame frame;
    frame.dlc = 2;
    const uint8_t commands[] = {0x01, 0x01, 0x02, 0x80, 0x81, 0x82};
    frame.data[0] = commands[in_.ConsumeIntegralInRange<int>(0, 5)];
    frame.data[1] = 0;
    deliver(frame, [](const can::CanFrame&) {});
  }

  void sync() {
    can::CanFrame frame;
    frame.id = 0x80;
    frame.dlc = in_.ConsumeBool() ? 0 : 1;
    frame.data[0] = in_.ConsumeIntegral<uint8_t>();
    deliver(frame, [](const can::CanFrame&) {});
  }

  void write_parameter() {
    if (pdo_parameters_.empty()) return;
    const Target target = pdo_parameters_[in_.ConsumeIntegralInRange<size_t>(0, pdo_parameters_.size() - 1)];
    const bool mapping = (target.index & 0x0200) != 0;  // 16xx / 1Axx
    uint32_t value = 0;
    uint8_t size = 4;
    if (mapping && target.sub == 0) {
      value = in_.ConsumeIntegralInRange<uint32_t>(0, 9);
      size = 1;
    } else if (mapping) {
      value = mapping_entry();
    } else if (target.sub == 1) {
      value = in_.ConsumeBool() ? (0x180u + 0x100u * in_.ConsumeIntegralInRange<uint32_t>(0, 7) + device_.node_id()) |
                                      (in_.ConsumeBool() ? canopen::kPdoCobIdInvalid : 0u)
                                : in_.ConsumeIntegral<uint32_t>();
    } else if (target.sub == 2) {
      value = in_.ConsumeIntegral<uint8_t>();
      size = 1;
    } else {
      value = in_.ConsumeIntegral<uint16_t>();
      size = 2;
    }
    sdo_write(target.index, target.sub, value, size);
  }

  // The CiA-301 sequence: invalidate, count 0, entries, count, valid again.
  void remap() {
    const bool receive = in_.ConsumeBool();
    const uint16_t number = in_.ConsumeIntegralInRange<uint16_t>(0, 3);
    const uint16_t axis_offset = static_cast<uint16_t>(0x40 * in_.ConsumeIntegralInRange<int>(0, 2));
    const uint16_t communication = static_cast<uint16_t>((receive ? 0x1400 : 0x1800) + number + axis_offset);
    const uint16_t mapping = static_cast<uint16_t>(communication + 0x200);
    const uint32_t cob_id = read_u32(communication, 1) & 0x1FFF'FFFF & ~canopen::kPdoCobIdNoRtr;
    sdo_write(communication, 1, cob_id | canopen::kPdoCobIdInvalid, 4);
    sdo_write(mapping, 0, 0, 1);
    const uint8_t count = in_.ConsumeIntegralInRange<uint8_t>(0, 8);
    for (uint8_t i = 1; i <= count; ++i) sdo_write(mapping, i, mapping_entry(), 4);
    sdo_write(mapping, 0, count, 1);
    if (receive) sdo_write(communication, 2, in_.ConsumeBool() ? 255 : in_.ConsumeIntegralInRange<uint8_t>(1, 3), 1);
    sdo_write(communication, 1, cob_id, 4);
  }

  void rpdo_frame() {
    can::CanFrame frame;
    const uint16_t number = in_.ConsumeIntegralInRange<uint16_t>(0, 3);
    const uint16_t axis_offset = static_cast<uint16_t>(0x40 * in_.ConsumeIntegralInRange<int>(0, 2));
    frame.id = read_u32(static_cast<uint16_t>(0x1400 + number + axis_offset), 1) & can::kMaxStandardId;
    if (in_.ConsumeIntegralInRange<int>(0, 7) == 0) frame.id = in_.ConsumeIntegralInRange<uint32_t>(0, 0x7FF);
    // SDO requests are canopen_sdo's business (a block upload answers with many frames).
    if (frame.id == canopen::kSdoRequestCobIdBase + device_.node_id()) return;
    frame.dlc = in_.ConsumeIntegralInRange<uint8_t>(0, 8);
    for (auto& b : frame.data) b = in_.ConsumeIntegral<uint8_t>();
    deliver(frame, [](const can::CanFrame&) {});
  }

  // The PDO parameters and the mappable objects of the dictionary: the object table is constant,
  // so they are listed once per process.
  struct Tables {
    std::vector<Target> pdo_parameters;
    std::vector<uint32_t> mappable;

    static const Tables& of(fuzz::Tmcm3216& device) {
      static const Tables tables = [&device] {
        Tables t;
        for (const auto& row : device.dictionary().rows()) {
          const uint8_t axes = row.info.axis_stride == 0 ? 1 : device.dictionary().axis_count();
          for (uint8_t axis = 0; axis < axes; ++axis) {
            const auto index = static_cast<uint16_t>(row.info.index + axis * row.info.axis_stride);
            if (is_pdo_parameter(index)) t.pdo_parameters.push_back({index, row.info.sub});
            if (row.info.pdo_mappable && canopen::is_numeric(row.info.type)) {
              t.mappable.push_back(static_cast<uint32_t>(index) << 16 | static_cast<uint32_t>(row.info.sub) << 8 |
                                   canopen::type_size(row.info.type) * 8u);
            }
          }
        }
        return t;
      }();
      return tables;
    }
  };

  FuzzedDataProvider& in_;
  fuzz::Tmcm3216Rig& rig_;
  fuzz::Tmcm3216& device_;
  const Tables& tables_;
  const std::vector<Target>& pdo_parameters_ = tables_.pdo_parameters;
  const std::vector<uint32_t>& mappable_ = tables_.mappable;
  fuzz::SdoClientView<fuzz::Tmcm3216> client_{device_};
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = fuzz::fresh_rig<fuzz::Tmcm3216Rig>();
  rig->can.frames.clear();
  PdoFuzzer(in, *rig).run();
  return 0;
}
