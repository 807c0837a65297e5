// `motwin sdo read|write` and `motwin nmt`: a CANopen master on a socketcand endpoint
// (docs/canopen.md). Exit status 0 on success, 1 when the node aborted the transfer (the abort
// code and its meaning on stderr), 2 for bad arguments, no connection or no answer.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli/bus_connection.h"
#include "cli/cli_errors.h"
#include "cli/commands.h"
#include "core/canopen/sdo_abort.h"
#include "host/can_endpoint.h"
#include "tools/canopen_client.h"

namespace motwin::cli {
namespace {

constexpr const char* kDefaultCan = kDefaultCanEndpoint;

struct Target {
  std::string can = kDefaultCan;
  int node = 1;
};

std::optional<uint32_t> parse_unsigned(const std::string& text, int base) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const unsigned long long value = std::strtoull(text.c_str() + (hex ? 2 : 0), &end, hex ? 16 : base);
  if (*end != '\0' || value > 0xFFFFFFFFull) return std::nullopt;
  return static_cast<uint32_t>(value);
}

// TYPE: u8 u16 u32 i8 i16 i32 (numbers), str (visible string), hex (raw bytes).
int type_size(const std::string& type) {
  if (type == "u8" || type == "i8") return 1;
  if (type == "u16" || type == "i16") return 2;
  if (type == "u32" || type == "i32") return 4;
  if (type == "str" || type == "hex") return 0;
  return -1;
}

std::string format_value(const std::vector<uint8_t>& data, const std::string& type) {
  if (type == "str") return std::string(data.begin(), data.end());
  if (type == "hex" || (type.empty() && data.size() > 4)) {
    std::string out;
    for (uint8_t b : data) {
      char byte[4];
      std::snprintf(byte, sizeof(byte), out.empty() ? "%02X" : " %02X", b);
      out += byte;
    }
    return out;
  }
  uint32_t raw = 0;
  for (size_t i = 0; i < data.size() && i < 4; ++i) raw |= static_cast<uint32_t>(data[i]) << (8 * i);
  if (type.empty()) {
    char text[16];
    std::snprintf(text, sizeof(text), "0x%0*X", static_cast<int>(data.size() * 2), raw);
    return text;
  }
  if (type[0] == 'i') {
    const int bits = type_size(type) * 8;
    int64_t value = raw;
    if (bits < 32 && (raw & (1u << (bits - 1)))) value -= int64_t{1} << bits;
    if (bits == 32) value = static_cast<int32_t>(raw);
    return std::to_string(value);
  }
  return std::to_string(raw);
}

// VALUE as TYPE puts it on the bus: little-endian numbers, the text of str, the bytes of hex
// (two hex digits each); nullopt when it does not fit the type.
std::optional<std::vector<uint8_t>> encode_value(const std::string& type, const std::string& value) {
  const int size = type_size(type);
  if (size < 0) return std::nullopt;
  if (type == "str") return std::vector<uint8_t>(value.begin(), value.end());
  std::vector<uint8_t> data;
  if (type == "hex") {
    if (value.empty() || value.size() % 2 != 0) return std::nullopt;
    for (size_t i = 0; i < value.size(); i += 2) {
      const std::optional<uint32_t> byte = parse_unsigned(value.substr(i, 2), 16);
      if (!byte) return std::nullopt;
      data.push_back(static_cast<uint8_t>(*byte));
    }
    return data;
  }
  const bool negative = !value.empty() && value[0] == '-';
  const std::optional<uint32_t> magnitude = parse_unsigned(negative ? value.substr(1) : value, 10);
  if (!magnitude || (negative && type[0] != 'i')) return std::nullopt;
  const uint32_t raw = negative ? static_cast<uint32_t>(-static_cast<int64_t>(*magnitude)) : *magnitude;
  for (int i = 0; i < size; ++i) data.push_back(static_cast<uint8_t>(raw >> (8 * i)));
  return data;
}

// The node's answer: the exit status, and the abort or the failure on stderr.
int report(const tools::SdoResult& result) {
  if (result.ok) return kExitSuccess;
  if (result.abort_code != 0) {
    char text[32];
    std::snprintf(text, sizeof(text), "0x%08X", result.abort_code);
    const std::string meaning = canopen::describe(result.abort_code);
    print_error(std::string("SDO abort ") + text + (meaning.empty() ? "" : " (" + meaning + ")"));
    return kExitModuleError;
  }
  print_error(result.error);
  return kExitUsageError;
}

}  // namespace

void add_canopen_commands(CLI::App& app, int& exit_status) {
  CLI::App* sdo = app.add_subcommand("sdo", "Read or write an object of a CANopen node over a socketcand endpoint");
  sdo->require_subcommand(1);

  struct ReadOptions {
    Target target;
    std::string index, sub, type;
  };
  auto read = std::make_shared<ReadOptions>();
  CLI::App* read_cmd = sdo->add_subcommand("read", "SDO upload: prints the value");
  read_cmd->add_option("--can", read->target.can, "Bus endpoint")->type_name("socketcand:HOST:PORT")->capture_default_str();
  read_cmd->add_option("node", read->target.node, "Node ID")->required()->check(CLI::Range(1, 127));
  read_cmd->add_option("index", read->index, "Object index in hex (1018 or 0x1018)")->required();
  read_cmd->add_option("sub", read->sub, "Sub-index (decimal or 0x..)")->required();
  read_cmd->add_option("type", read->type, "u8 u16 u32 i8 i16 i32 str hex (default: hex number, or bytes)");
  read_cmd->callback([read, &exit_status] {
    const std::optional<uint32_t> index = parse_unsigned(read->index, 16);
    const std::optional<uint32_t> sub = parse_unsigned(read->sub, 10);
    if (!index || *index > 0xFFFF || !sub || *sub > 0xFF || (!read->type.empty() && type_size(read->type) < 0)) {
      exit_status = usage_error("expected NODE INDEX SUB [u8|u16|u32|i8|i16|i32|str|hex]");
      return;
    }
    const Result<std::unique_ptr<tools::SocketcandClient>> bus = connect_can(read->target.can);
    if (!bus) {
      exit_status = usage_error(bus.error());
      return;
    }
    const tools::SdoResult result = tools::sdo_upload(**bus, static_cast<uint8_t>(read->target.node),
                                                      static_cast<uint16_t>(*index), static_cast<uint8_t>(*sub));
    exit_status = report(result);
    if (result.ok) std::cout << format_value(result.data, read->type) << '\n';
  });

  struct WriteOptions {
    Target target;
    std::string index, sub, type, value;
  };
  auto write = std::make_shared<WriteOptions>();
  CLI::App* write_cmd = sdo->add_subcommand("write", "SDO download of a value of the given type");
  write_cmd->add_option("--can", write->target.can, "Bus endpoint")->type_name("socketcand:HOST:PORT")->capture_default_str();
  write_cmd->add_option("node", write->target.node, "Node ID")->required()->check(CLI::Range(1, 127));
  write_cmd->add_option("index", write->index, "Object index in hex")->required();
  write_cmd->add_option("sub", write->sub, "Sub-index")->required();
  write_cmd->add_option("type", write->type, "u8 u16 u32 i8 i16 i32 str hex")->required();
  write_cmd->add_option("value", write->value, "Value (decimal or 0x..; text for str; hex digits for hex)")->required();
  write_cmd->callback([write, &exit_status] {
    const std::optional<uint32_t> index = parse_unsigned(write->index, 16);
    const std::optional<uint32_t> sub = parse_unsigned(write->sub, 10);
    const std::optional<std::vector<uint8_t>> data = encode_value(write->type, write->value);
    if (!index || *index > 0xFFFF || !sub || *sub > 0xFF || !data) {
      exit_status = usage_error("expected NODE INDEX SUB TYPE VALUE with TYPE u8|u16|u32|i8|i16|i32|str|hex");
      return;
    }
    const Result<std::unique_ptr<tools::SocketcandClient>> bus = connect_can(write->target.can);
    if (!bus) {
      exit_status = usage_error(bus.error());
      return;
    }
    exit_status = report(tools::sdo_download(**bus, static_cast<uint8_t>(write->target.node),
                                             static_cast<uint16_t>(*index), static_cast<uint8_t>(*sub), *data));
  });

  struct NmtOptions {
    Target target;
    std::string command;
  };
  auto nmt = std::make_shared<NmtOptions>();
  CLI::App* nmt_cmd = app.add_subcommand("nmt", "Send an NMT command (node 0: all nodes) over a socketcand endpoint");
  nmt_cmd->add_option("--can", nmt->target.can, "Bus endpoint")->type_name("socketcand:HOST:PORT")->capture_default_str();
  nmt_cmd->add_option("command", nmt->command, "start, stop, preop, reset or reset-comm")
      ->required()
      ->check(CLI::IsMember({"start", "stop", "preop", "reset", "reset-comm"}));
  nmt_cmd->add_option("node", nmt->target.node, "Node ID, 0 for all")->required()->check(CLI::Range(0, 127));
  nmt_cmd->callback([nmt, &exit_status] {
    const uint8_t code = nmt->command == "start"  ? 0x01
                         : nmt->command == "stop" ? 0x02
                         : nmt->command == "preop" ? 0x80
                         : nmt->command == "reset" ? 0x81
                                                   : 0x82;
    const Result<std::unique_ptr<tools::SocketcandClient>> bus = connect_can(nmt->target.can);
    if (!bus) {
      exit_status = usage_error(bus.error());
      return;
    }
    const uint8_t data[2] = {code, static_cast<uint8_t>(nmt->target.node)};
    exit_status = (*bus)->send(can::make_frame(0x000, data, 2)) ? kExitSuccess
                                                                : usage_error("cannot send to the socketcand server");
  });
}

}  // namespace motwin::cli
