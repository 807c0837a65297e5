// The options a --tmcl-tcp or --tmcl-pty argument may carry after its address, the same for
// both: "127.0.0.1:5000,echo", "/tmp/tmcm3216,echo". The first comma ends the address (a pty's
// LINK therefore has none); each word after a comma is an option:
//   echo   every byte the host sends comes back to it at once, as an RS485 transceiver hands the
//          host back what it transmits (LineEcho::kTransceiver; Zephyr's TMCM RS485 bus driver
//          needs it).
#pragma once

#include <string>
#include <string_view>

#include "host/tmcl_host_service.h"
#include "types/result.h"

namespace motwin::host {

struct TmclEndpointArgument {
  std::string address;  // HOST:PORT or LINK, as given
  LineEcho echo = LineEcho::kNone;
};

// "ADDRESS[,OPTION...]"; an empty address or an unknown option is an error naming the options.
Result<TmclEndpointArgument> parse_tmcl_endpoint_argument(std::string_view text);

// What the `endpoint` line of serve says after the address: "" or " echo".
std::string describe_line_echo(LineEcho echo);

}  // namespace motwin::host
