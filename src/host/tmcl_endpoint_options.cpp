#include "host/tmcl_endpoint_options.h"

namespace motwin::host {

Result<TmclEndpointArgument> parse_tmcl_endpoint_argument(std::string_view text) {
  TmclEndpointArgument argument;
  const size_t comma = text.find(',');
  argument.address = std::string(text.substr(0, comma));
  if (argument.address.empty()) {
    return Error{"expected an address before the options (ADDRESS[,echo]), got \"" + std::string(text) + "\""};
  }
  std::string_view options = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
  while (comma != std::string_view::npos) {
    const size_t next = options.find(',');
    const std::string_view option = options.substr(0, next);
    if (option != "echo") {
      return Error{"unknown option \"" + std::string(option) + "\" in \"" + std::string(text) +
                   "\": the options after the address are echo (and the address has no comma)"};
    }
    argument.echo = LineEcho::kTransceiver;
    if (next == std::string_view::npos) break;
    options.remove_prefix(next + 1);
  }
  return argument;
}

std::string describe_line_echo(LineEcho echo) { return echo == LineEcho::kTransceiver ? " echo" : ""; }

}  // namespace motwin::host
