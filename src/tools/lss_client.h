// A CiA-305 LSS master for the command line (`motwin lss`): requests on 0x7E5, answers on 0x7E4,
// over a socketcand connection (tools/canopen_client.h). Written from CiA-305: switch state
// global and selective, configure node ID and bit timing, activate bit timing, store, inquire
// identity and node ID, and fastscan to find an unconfigured slave's identity.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "tools/canopen_client.h"
#include "types/result.h"

namespace motwin::tools {

inline constexpr uint32_t kLssMasterId = 0x7E5;
inline constexpr uint32_t kLssSlaveId = 0x7E4;

struct LssIdentityNumbers {
  uint32_t vendor_id = 0;
  uint32_t product_code = 0;
  uint32_t revision_number = 0;
  uint32_t serial_number = 0;
};

// The outcome of one LSS service: `ok`, or `error` (no answer, or the slave's error code). Not
// a Result: the slave's error code and an inquired value are answers the caller uses.
struct LssResult {
  bool ok = false;
  uint8_t error_code = 0;       // the slave answered with this error (configure/store)
  uint32_t value = 0;           // inquire: the value
  std::string error;            // text for the user
};

class LssMaster {
 public:
  explicit LssMaster(SocketcandClient& bus, int timeout_ms = 1000) : bus_(bus), timeout_ms_(timeout_ms) {}

  // No answer in CiA-305: the result only says whether the frame went out.
  LssResult switch_global(bool configuration);
  // Vendor, product, revision, serial; answered 0x44 by the one matching slave.
  LssResult switch_selective(const LssIdentityNumbers& identity);
  LssResult configure_node_id(uint8_t node_id);
  // Table 0 index: 0 = 1000, 1 = 800, 2 = 500, 3 = 250, 4 = 125, 6 = 50, 7 = 20, 8 = 10 kbit/s.
  LssResult configure_bit_timing(uint8_t table_index);
  LssResult activate_bit_timing(uint16_t switch_delay_ms);
  LssResult store_configuration();
  // `what`: 0x5A vendor, 0x5B product, 0x5C revision, 0x5D serial, 0x5E node ID.
  LssResult inquire(uint8_t command);

  // Fastscan (CiA-305 8.4.2): finds the identity of one unconfigured slave in waiting state and
  // leaves that slave in configuration state. `step_timeout_ms` bounds the wait for an answer
  // to each probe (no answer is part of the algorithm); a tenth of it (at least 2 ms) of quiet
  // ends the draining of further slaves' late answers before the next probe. Fails when no
  // slave answered.
  Result<LssIdentityNumbers> fastscan(int step_timeout_ms);

  // CiA-305 table 0 bit rates (kbit/s) to index; nullopt for others.
  static std::optional<uint8_t> bit_timing_index(uint32_t bit_rate_kbit);

 private:
  Result<void> send(const std::array<uint8_t, 8>& data, int settle_ms = 2);
  // The next answer with command specifier `command` within `timeout_ms`.
  std::optional<can::CanFrame> await(uint8_t command, int timeout_ms);
  LssResult confirmed(const std::array<uint8_t, 8>& request, const char* what);

  SocketcandClient& bus_;
  int timeout_ms_;
};

}  // namespace motwin::tools
