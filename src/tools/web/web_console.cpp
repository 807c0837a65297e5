#include "tools/web/web_console.h"
#include "tools/web/web_json.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/canopen/sdo_abort.h"
#include "core/tmcl/serial_link.h"
#include "core/tmcl/status.h"
#include "host/tmcl_can_node.h"
#include "tools/canopen_object_text.h"
#include "tools/tmcl_mnemonics.h"
#include "tools/web/tmcl_can_port.h"
#include "tools/web/web_datalogger.h"
#include "tools/web/web_program.h"

namespace motwin::tools::web {

using Json = nlohmann::json;

namespace {

// --- TMCL through the module's host service --------------------------------------------------

// The console's own connection to a TMCL module: requests go in as 9-byte frames, in order, as
// many as the service takes; replies come back in the same order.
class TmclPort final : public host::ReplyChannel, public TmclRequests {
 public:
  using EventListener = std::function<void(const TmclAnswer&)>;

  TmclPort(host::TmclHostService& service, uint8_t module_address, EventListener on_event)
      : service_(service), module_address_(module_address), on_event_(std::move(on_event)) {
    // Background: the console's reads are no host in a request/reply exchange (its pages' own
    // requests arrive on a descriptor and open the busy-poll window as any host input does).
    channel_ = service_.open_channel(*this, tmcl::SerialFrameDecoder::kDefaultResyncGapUs,
                                     host::ChannelTraffic::kBackground);
  }
  ~TmclPort() { service_.close_channel(channel_); }
  TmclPort(const TmclPort&) = delete;
  TmclPort& operator=(const TmclPort&) = delete;

  void request(const tmcl::Instruction& instruction, Done done) override {
    (held_ ? held_back_ : waiting_).push_back(Pending{instruction, std::move(done), false, {}});
    feed();
  }
  bool hold() override { return !std::exchange(held_, true); }
  void held_request(const tmcl::Instruction& instruction, Done done) override {
    waiting_.push_back(Pending{instruction, std::move(done), false, {}});
    feed();
  }

  // A read of a subscribed value: a read of the same parameter that is waiting and not yet served
  // answers `done` too (its answer comes from after both asked, as fresh as a read of its own),
  // so pages that show the same rows cost the module one read per row and period.
  void shared_read(const tmcl::Instruction& instruction, Done done) override {
    const auto same = [&instruction](const Pending& pending) {
      return pending.shared && pending.instruction.command == instruction.command &&
             pending.instruction.type == instruction.type && pending.instruction.motor_bank == instruction.motor_bank;
    };
    if (const auto found = std::find_if(waiting_.begin(), waiting_.end(), same); found != waiting_.end()) {
      found->sharers.push_back(std::move(done));
      return;
    }
    // The first in service may have been served already, its reply held for the telegram pause.
    if (in_service_.size() > 1) {
      const auto found = std::find_if(in_service_.begin() + 1, in_service_.end(), same);
      if (found != in_service_.end()) {
        found->sharers.push_back(std::move(done));
        return;
      }
    }
    // Held (a download): after it, or the module would store the read as an instruction.
    (held_ ? held_back_ : waiting_).push_back(Pending{instruction, std::move(done), true, {}});
    feed();
  }
  void release() override {
    held_ = false;
    while (!held_back_.empty()) {
      waiting_.push_back(std::move(held_back_.front()));
      held_back_.pop_front();
    }
    feed();
  }

  void send_reply(const uint8_t* bytes, size_t length) override {
    received_.insert(received_.end(), bytes, bytes + length);
    while (received_.size() >= tmcl::kFrameLength) {
      tmcl::Frame frame{};
      std::copy_n(received_.begin(), tmcl::kFrameLength, frame.begin());
      received_.erase(received_.begin(), received_.begin() + tmcl::kFrameLength);
      on_frame(frame);
    }
  }

  void on_request_served() override {
    if (replied_not_served_ > 0) {
      --replied_not_served_;
    } else if (!in_service_.empty()) {
      Pending served = std::move(in_service_.front());
      in_service_.pop_front();
      served.answer(TmclAnswer{});
    }
    feed();
  }

 private:
  struct Pending {
    tmcl::Instruction instruction;
    Done done;
    bool shared = false;          // a shared_read()
    std::vector<Done> sharers;    // later askers of the same read

    void answer(const TmclAnswer& answer) {
      done(answer);
      for (const Done& sharer : sharers) sharer(answer);
    }
  };

  void on_frame(const tmcl::Frame& frame) {
    TmclAnswer answer;
    answer.replied = true;
    answer.status = frame[2];
    answer.command = frame[3];
    answer.value = static_cast<int32_t>(static_cast<uint32_t>(frame[4]) << 24 | static_cast<uint32_t>(frame[5]) << 16 |
                                        static_cast<uint32_t>(frame[6]) << 8 | frame[7]);
    const bool expected = !in_service_.empty();
    const tmcl::Instruction* asked = expected ? &in_service_.front().instruction : nullptr;
    // A delayed reply of command 138 (target reached) arrives whenever it is due.
    if (asked == nullptr || (answer.command == tmcl::command::kRequestPositionReachedEvent &&
                             asked->command != tmcl::command::kRequestPositionReachedEvent &&
                             !(asked->command == tmcl::command::kGetFirmwareVersion && asked->type == 0))) {
      if (on_event_) on_event_(answer);
      return;
    }
    if (asked->command == tmcl::command::kGetFirmwareVersion && asked->type == 0) {
      std::string version;
      for (size_t i = 1; i < tmcl::kFrameLength; ++i) version += static_cast<char>(frame[i]);
      answer.version = version;
    }
    Pending done = std::move(in_service_.front());
    in_service_.pop_front();
    ++replied_not_served_;
    done.answer(answer);
  }

  // The service reads a channel's requests as its queue has room, like a client's socket.
  void feed() {
    while (!waiting_.empty() && service_.has_room(channel_)) {
      const tmcl::Frame frame = tmcl::encode_request(module_address_, waiting_.front().instruction);
      in_service_.push_back(std::move(waiting_.front()));
      waiting_.pop_front();
      service_.receive(channel_, frame.data(), frame.size(), host::monotonic_now_us());
    }
  }

  host::TmclHostService& service_;
  uint8_t module_address_;
  EventListener on_event_;
  tmcl::ChannelId channel_ = 0;
  std::deque<Pending> waiting_;
  bool held_ = false;
  std::deque<Pending> held_back_;  // requests made while held
  std::deque<Pending> in_service_;
  std::vector<uint8_t> received_;
  size_t replied_not_served_ = 0;
};

// --- SDO and NMT on the bus --------------------------------------------------------------------

struct SdoAnswer {
  bool answered = false;    // false: `error` says why (a timeout, a protocol error)
  uint32_t abort_code = 0;  // the node aborted
  std::vector<uint8_t> data;
  std::string error;
};

// A CANopen master's SDO client, one transfer per node at a time (CiA-301: one server channel),
// expedited downloads and expedited or segmented uploads.
class SdoMaster final : public host::CanBusEndpoint {
 public:
  using Done = std::function<void(const SdoAnswer&)>;

  SdoMaster(host::CanBus& bus, host::EventLoop& loop) : bus_(bus), loop_(loop) { id_ = bus_.attach(*this); }
  ~SdoMaster() {
    *alive_ = false;
    bus_.detach(id_);
    for (auto& [node, transfers] : nodes_) {
      if (!transfers.empty() && transfers.front().timer) loop_.cancel_timer(*transfers.front().timer);
    }
  }
  SdoMaster(const SdoMaster&) = delete;
  SdoMaster& operator=(const SdoMaster&) = delete;

  void upload(uint8_t node, uint16_t index, uint8_t sub, Done done) {
    enqueue(node, Transfer{index, sub, false, {}, std::move(done), false, 0, std::nullopt, false, {}});
  }
  // An upload of a subscribed value: one of the same object waiting to begin answers `done` too
  // (as TmclPort::shared_read), so pages that show the same objects share their SDO traffic.
  void shared_upload(uint8_t node, uint16_t index, uint8_t sub, Done done) {
    std::deque<Transfer>& transfers = nodes_[node];
    // The first has begun: its request is on the bus already.
    for (size_t i = 1; i < transfers.size(); ++i) {
      Transfer& transfer = transfers[i];
      if (transfer.shared && transfer.index == index && transfer.sub == sub) {
        transfer.sharers.push_back(std::move(done));
        return;
      }
    }
    enqueue(node, Transfer{index, sub, false, {}, std::move(done), false, 0, std::nullopt, true, {}});
  }
  void download(uint8_t node, uint16_t index, uint8_t sub, std::vector<uint8_t> data, Done done) {
    enqueue(node, Transfer{index, sub, true, std::move(data), std::move(done), false, 0, std::nullopt, false, {}});
  }
  void nmt(uint8_t command, uint8_t node) {
    const uint8_t bytes[2] = {command, node};
    transmit(can::make_frame(0x000, bytes, 2));
  }
  // The NMT state the node last announced (boot-up: 0, heartbeat: 4, 5, 127); none yet: nullopt.
  std::optional<uint8_t> announced_state(uint8_t node) const {
    const auto found = states_.find(node);
    if (found == states_.end()) return std::nullopt;
    return found->second;
  }

  // Every frame the console hears on the bus and every one it sends (the bus does not echo a
  // client's own frames), for the `monitor` op.
  std::function<void(const can::CanFrame&, uint64_t timestamp_us)> monitor;

  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override {
    if (monitor) monitor(frame, timestamp_us);
    if (frame.extended || frame.rtr) return;
    if (frame.id > 0x700 && frame.id <= 0x77F && frame.dlc >= 1) {
      states_[static_cast<uint8_t>(frame.id - 0x700)] = static_cast<uint8_t>(frame.data[0] & 0x7F);
      return;
    }
    if (frame.id <= 0x580 || frame.id > 0x5FF || frame.dlc != 8) return;
    const uint8_t node = static_cast<uint8_t>(frame.id - 0x580);
    auto found = nodes_.find(node);
    if (found == nodes_.end() || found->second.empty()) return;
    Transfer& transfer = found->second.front();
    const uint8_t specifier = frame.data[0] >> 5;
    if (specifier == 4) return finish(node, SdoAnswer{true, read_u32(frame.data + 4), {}, {}});
    if (transfer.segmented) {
      if (specifier != 0 || ((frame.data[0] >> 4) & 1) != transfer.toggle) {
        return abort_transfer(node, canopen::SdoAbort::kToggleBit);
      }
      const uint8_t unused = (frame.data[0] >> 1) & 7;
      transfer.data.insert(transfer.data.end(), frame.data + 1, frame.data + 8 - unused);
      if (frame.data[0] & 1) return finish(node, SdoAnswer{true, 0, std::move(transfer.data), {}});
      if (transfer.data.size() > 4096) return abort_transfer(node, canopen::SdoAbort::kOutOfMemory);
      transfer.toggle ^= 1;
      return send_segment_request(node, transfer);
    }
    if (!multiplexer_matches(frame, transfer)) return;
    if (transfer.download) {
      if (specifier != 3) return abort_transfer(node, canopen::SdoAbort::kUnknownCommand);
      return finish(node, SdoAnswer{true, 0, {}, {}});
    }
    if (specifier != 2) return abort_transfer(node, canopen::SdoAbort::kUnknownCommand);
    const bool expedited = frame.data[0] & 2;
    if (expedited) {
      const size_t size = (frame.data[0] & 1) ? 4u - ((frame.data[0] >> 2) & 3) : 4u;
      return finish(node, SdoAnswer{true, 0, std::vector<uint8_t>(frame.data + 4, frame.data + 4 + size), {}});
    }
    transfer.segmented = true;
    transfer.toggle = 0;
    transfer.data.clear();
    send_segment_request(node, transfer);
  }

 private:
  struct Transfer {
    uint16_t index;
    uint8_t sub;
    bool download;
    std::vector<uint8_t> data;
    Done done;
    bool segmented = false;
    uint8_t toggle = 0;
    std::optional<host::EventLoop::TimerId> timer;
    bool shared = false;        // a shared_upload()
    std::vector<Done> sharers;  // later askers of the same upload
  };

  static uint32_t read_u32(const uint8_t* bytes) {
    return static_cast<uint32_t>(bytes[0]) | static_cast<uint32_t>(bytes[1]) << 8 |
           static_cast<uint32_t>(bytes[2]) << 16 | static_cast<uint32_t>(bytes[3]) << 24;
  }
  static bool multiplexer_matches(const can::CanFrame& frame, const Transfer& transfer) {
    return (frame.data[1] | frame.data[2] << 8) == transfer.index && frame.data[3] == transfer.sub;
  }

  void enqueue(uint8_t node, Transfer transfer) {
    std::deque<Transfer>& transfers = nodes_[node];
    transfers.push_back(std::move(transfer));
    if (transfers.size() == 1) begin(node);
  }

  void begin(uint8_t node) {
    Transfer& transfer = nodes_[node].front();
    uint8_t bytes[8] = {0, static_cast<uint8_t>(transfer.index & 0xFF), static_cast<uint8_t>(transfer.index >> 8),
                        transfer.sub, 0, 0, 0, 0};
    if (transfer.download) {
      const size_t size = transfer.data.size();
      // Expedited, size indicated: 1..4 bytes.
      bytes[0] = static_cast<uint8_t>(0x23 | ((4 - size) << 2));
      std::copy(transfer.data.begin(), transfer.data.end(), bytes + 4);
    } else {
      bytes[0] = 0x40;
    }
    arm_timeout(node, transfer);
    transmit(can::make_frame(0x600u + node, bytes, 8));
  }

  void send_segment_request(uint8_t node, Transfer& transfer) {
    const uint8_t bytes[8] = {static_cast<uint8_t>(0x60 | (transfer.toggle << 4)), 0, 0, 0, 0, 0, 0, 0};
    arm_timeout(node, transfer);
    transmit(can::make_frame(0x600u + node, bytes, 8));
  }

  void arm_timeout(uint8_t node, Transfer& transfer) {
    if (transfer.timer) loop_.cancel_timer(*transfer.timer);
    transfer.timer = loop_.add_timer_after(WebConsole::kSdoTimeoutUs, [this, node, alive = alive_] {
      if (!*alive) return;
      nodes_[node].front().timer.reset();
      finish(node, SdoAnswer{false, 0, {}, "no answer from node " + std::to_string(node)});
    });
  }

  void abort_transfer(uint8_t node, canopen::SdoAbort abort) {
    const Transfer& transfer = nodes_[node].front();
    const uint32_t abort_code = canopen::code(abort);
    const uint8_t bytes[8] = {0x80,
                              static_cast<uint8_t>(transfer.index & 0xFF),
                              static_cast<uint8_t>(transfer.index >> 8),
                              transfer.sub,
                              static_cast<uint8_t>(abort_code),
                              static_cast<uint8_t>(abort_code >> 8),
                              static_cast<uint8_t>(abort_code >> 16),
                              static_cast<uint8_t>(abort_code >> 24)};
    transmit(can::make_frame(0x600u + node, bytes, 8));
    finish(node, SdoAnswer{false, 0, {}, "SDO protocol error (the console aborted with " + std::to_string(abort_code) + ")"});
  }

  void transmit(const can::CanFrame& frame) {
    bus_.send(id_, frame);
    if (monitor) monitor(frame, bus_.now_us());
  }

  void finish(uint8_t node, SdoAnswer answer) {
    std::deque<Transfer>& transfers = nodes_[node];
    Transfer transfer = std::move(transfers.front());
    transfers.pop_front();
    if (transfer.timer) loop_.cancel_timer(*transfer.timer);
    if (!transfers.empty()) begin(node);
    transfer.done(answer);
    for (const Done& sharer : transfer.sharers) sharer(answer);
  }

  host::CanBus& bus_;
  host::EventLoop& loop_;
  host::CanBus::EndpointId id_ = 0;
  std::map<uint8_t, std::deque<Transfer>> nodes_;
  std::map<uint8_t, uint8_t> states_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

// --- Helpers -----------------------------------------------------------------------------------

std::string hex_text(const std::vector<uint8_t>& data) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string text;
  for (uint8_t byte : data) {
    text += kDigits[byte >> 4];
    text += kDigits[byte & 15];
  }
  return text;
}

std::string abort_text(uint32_t abort_code) {
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "0x%08X", abort_code);
  return buffer;
}

std::string_view nmt_state_name(uint8_t state) {
  switch (state) {
    case 0: return "pre-operational";  // the boot-up message: the node has entered it
    case 4: return "stopped";
    case 5: return "operational";
    case 127: return "pre-operational";
    default: return "unknown";
  }
}

struct RequestError {
  std::string message;
};

// An axis parameter of a motor the module does not have: refused before anything is sent (a TMCL
// host that sends it gets status 4, invalid value).
std::string motor_error(const ConsoleTarget& target, uint8_t motor) {
  return "\"axis\": no motor " + std::to_string(motor) + " on " + target.name + " (" +
         (target.motor_count == 1 ? std::string("one motor: 0")
                                  : std::to_string(target.motor_count) + " motors: 0.." +
                                        std::to_string(target.motor_count - 1)) +
         ")";
}

}  // namespace

// --- Targets -----------------------------------------------------------------------------------

ConsoleTarget tmcl_target(const host::ModuleDescriptor& descriptor, std::string name, std::string firmware,
                          std::string_view firmware_generation, uint8_t motor_count, host::TmclHostService* service,
                          host::TmclCanNode* can_node) {
  ConsoleTarget target;
  target.name = std::move(name);
  target.module = std::string(descriptor.name);
  target.product_name = std::string(descriptor.product_name);
  target.firmware = std::move(firmware);
  Result<host::ModuleParameterListing> listing = host::firmware_listing(descriptor, firmware_generation);
  target.listing = listing ? std::move(*listing) : descriptor.listing();
  target.tmcl = service;
  target.tmcl_can = can_node;
  target.motor_count = motor_count;
  return target;
}

ConsoleTarget canopen_target(const host::ModuleDescriptor& descriptor, std::string name, std::string firmware,
                             uint8_t node_id) {
  ConsoleTarget target;
  target.name = std::move(name);
  target.module = std::string(descriptor.name);
  target.product_name = std::string(descriptor.product_name);
  target.firmware = std::move(firmware);
  target.listing = descriptor.listing();
  target.canopen_node_id = node_id;
  // Its axes: the dictionary's objects name theirs (6041, 6841, 7041 on the TMCM-3216).
  for (const host::ObjectSection& section : target.listing.object_sections) {
    for (const host::DictionaryObject& object : section.objects) {
      target.motor_count = std::max<uint8_t>(target.motor_count, static_cast<uint8_t>(object.axis + 1));
    }
  }
  return target;
}

// --- The console ------------------------------------------------------------------------------

class WebConsole::Impl {
 public:
  class Session;

  // What a reply callback keeps of its session: it may close before the module answers.
  struct SessionLink {
    Session* session = nullptr;
  };

  Impl(host::EventLoop& loop, std::function<uint64_t()> sim_time_us, std::vector<ConsoleTarget> targets,
       host::CanBus* bus)
      : loop_(loop), sim_time_us_(std::move(sim_time_us)), targets_(std::move(targets)) {
    for (size_t i = 0; i < targets_.size(); ++i) {
      const ConsoleTarget& target = targets_[i];
      if (target.tmcl != nullptr) {
        ports_[i] = std::make_unique<TmclPort>(*target.tmcl, target.module_address,
                                               [this, i](const TmclAnswer& answer) { broadcast_event(i, answer); });
      } else if (target.tmcl_can != nullptr && bus != nullptr) {
        // Its frames reach the bus monitor through the SDO client, which hears them like any other.
        ports_[i] = std::make_unique<TmclCanPort>(
            *bus, loop_, [node = target.tmcl_can] { return node->settings(); },
            [this, i](const TmclAnswer& answer) { broadcast_event(i, answer); });
      }
    }
    if (bus != nullptr) {
      sdo_ = std::make_unique<SdoMaster>(*bus, loop_);
      sdo_->monitor = [this](const can::CanFrame& frame, uint64_t timestamp_us) {
        broadcast_frame(frame, timestamp_us);
      };
    }
  }

  ~Impl() {
    // Sessions end first (the server closes them); what is left is cut off here.
    for (Session* session : sessions_) session_detached(session);
  }

  host::EventLoop& loop() { return loop_; }
  uint64_t sim_time_us() const { return sim_time_us_ ? sim_time_us_() : 0; }
  const std::vector<ConsoleTarget>& targets() const { return targets_; }

  // The target a request names ("module": N), or why not.
  const ConsoleTarget* target_of(const Json& request, size_t& index, std::string& error) const {
    const std::optional<int64_t> number = integer_field(request, "module");
    if (!number) {
      if (targets_.size() == 1 && request.find("module") == request.end()) {
        index = 0;
        return &targets_[0];
      }
      error = "\"module\": expected the number of a module from \"list\"";
      return nullptr;
    }
    if (*number < 0 || static_cast<size_t>(*number) >= targets_.size()) {
      error = "no module " + std::to_string(*number) + " (the list has " + std::to_string(targets_.size()) + ")";
      return nullptr;
    }
    index = static_cast<size_t>(*number);
    return &targets_[index];
  }

  TmclRequests* port(size_t index) {
    const auto found = ports_.find(index);
    return found == ports_.end() ? nullptr : found->second.get();
  }
  SdoMaster* sdo() { return sdo_.get(); }

  void session_attached(Session* session) { sessions_.insert(session); }
  void session_detached(Session* session) { sessions_.erase(session); }

  void broadcast_event(size_t index, const TmclAnswer& answer);
  void broadcast_frame(const can::CanFrame& frame, uint64_t timestamp_us);

  // The dictionary entry of a CANopen target, or nullptr.
  const host::DictionaryEntry* entry(const ConsoleTarget& target, uint16_t index, uint8_t sub) const {
    for (const host::ObjectSection& section : target.listing.object_sections) {
      for (const host::DictionaryObject& object : section.objects) {
        if (object.index != index) continue;
        for (const host::DictionaryEntry& entry : object.entries) {
          if (entry.info.sub == sub) return &entry;
        }
      }
    }
    return nullptr;
  }

 private:
  host::EventLoop& loop_;
  std::function<uint64_t()> sim_time_us_;
  std::vector<ConsoleTarget> targets_;
  std::map<size_t, std::unique_ptr<TmclRequests>> ports_;
  std::unique_ptr<SdoMaster> sdo_;
  std::set<Session*> sessions_;
};

namespace {

Json listing_json(const ConsoleTarget& target) {
  Json sections = Json::array();
  for (const host::ParameterSection& section : target.listing.sections) {
    Json parameters = Json::array();
    for (const host::ListedParameter& parameter : section.parameters) {
      for (uint32_t number = parameter.first_number; number <= parameter.last_number; ++number) {
        parameters.push_back({{"number", number},
                              {"name", parameter.name},
                              {"unit", parameter.unit},
                              {"min", parameter.min},
                              {"max", parameter.max},
                              {"default", parameter.default_value},
                              {"access", parameter.access},
                              {"description", parameter.description}});
      }
    }
    Json json_section = {{"title", section.title},
                         {"kind", section.kind == host::ParameterKind::kAxis ? "axis" : "global"},
                         {"parameters", std::move(parameters)}};
    if (section.bank) json_section["bank"] = *section.bank;
    sections.push_back(std::move(json_section));
  }
  for (const host::ObjectSection& section : target.listing.object_sections) {
    Json objects = Json::array();
    for (const host::DictionaryObject& object : section.objects) {
      for (const host::DictionaryEntry& entry : object.entries) {
        const canopen::EntryInfo& info = entry.info;
        std::string name(info.object_name);
        if (info.code != canopen::ObjectCode::kVar) name += ": " + std::string(info.name);
        Json row = {{"index", object.index},
                    {"sub", info.sub},
                    {"name", name},
                    {"type", std::string(data_type_name(info.type))},
                    {"access", std::string(access_text(info.access))},
                    {"pdo_mappable", info.pdo_mappable},
                    {"axis", object.axis}};
        if (canopen::is_numeric(info.type)) {
          int64_t default_value = entry.default_value;
          if (info.default_plus_node_id && target.canopen_node_id) default_value += *target.canopen_node_id;
          row["min"] = info.min;
          row["max"] = info.max;
          row["default"] = default_value;
        } else {
          row["default"] = entry.text;
        }
        objects.push_back(std::move(row));
      }
    }
    sections.push_back({{"title", section.title}, {"kind", "objects"}, {"objects", std::move(objects)}});
  }
  return sections;
}

}  // namespace

class WebConsole::Impl::Session final : public host::web::WebSessionHandler {
 public:
  Session(Impl& console, host::web::WebConnection& connection)
      : console_(console), connection_(connection), link_(std::make_shared<SessionLink>(SessionLink{this})) {
    console_.session_attached(this);
  }
  ~Session() override {
    link_->session = nullptr;
    stop_subscription();
    stop_monitor();
    console_.session_detached(this);
  }

  void on_message(std::string_view text) override {
    Json request = Json::parse(text, nullptr, false);
    if (request.is_discarded() || !request.is_object()) {
      return send(Json{{"id", nullptr}, {"ok", false}, {"error", "not a JSON object"}});
    }
    Json id = request.contains("id") ? request["id"] : Json(nullptr);
    if (!id.is_null() && !id.is_number_integer() && !id.is_string()) id = nullptr;
    if (pending_ >= kMaxPendingRequestsPerSession) {
      return send(Json{{"id", id}, {"ok", false}, {"error", "too many requests waiting; wait for replies"}});
    }
    const auto op = request.find("op");
    if (op == request.end() || !op->is_string()) {
      return send(Json{{"id", id}, {"ok", false}, {"error", "\"op\": expected a string"}});
    }
    const std::string name = op->get<std::string>();
    std::string error;
    if (name == "list") return reply_list(id);
    if (name == "nmt_state") return reply_nmt_state(id);
    if (name == "get" || name == "set" || name == "store" || name == "restore") {
      error = parameter_op(name, request, id);
    } else if (name == "tmcl") {
      error = tmcl_op(request, id);
    } else if (name == "sdo_read" || name == "sdo_write") {
      error = sdo_op(name == "sdo_write", request, id);
    } else if (name == "nmt") {
      error = nmt_op(request, id);
    } else if (name == "subscribe") {
      error = subscribe_op(request, id);
    } else if (name == "unsubscribe") {
      stop_subscription();
      return send(Json{{"id", id}, {"ok", true}});
    } else if (name == "monitor") {
      error = monitor_op(request, id);
    } else if (name == "datalogger") {
      error = datalogger_op(request, id);
    } else if (is_world_op(name)) {
      error = world_request(name, request, id);
    } else if (is_program_op(name)) {
      error = program_op(name, request, id);
    } else {
      error = "unknown op \"" + name + "\" (list, get, set, store, restore, tmcl, sdo_read, sdo_write, nmt, "
              "subscribe, unsubscribe, monitor, datalogger, nmt_state, world, world_set, " +
              std::string(kProgramOpNames) + ")";
    }
    if (!error.empty()) send(Json{{"id", id}, {"ok", false}, {"error", error}});
  }

  void send_event(size_t module, const TmclAnswer& answer) {
    send(Json{{"push", "event"},
              {"module", module},
              {"command", answer.command},
              {"status", answer.status},
              {"value", answer.value},
              {"sim_time_us", console_.sim_time_us()}});
  }

 private:
  // One thing to read for a subscription or a get: a TMCL parameter or a CANopen object.
  struct Item {
    size_t module = 0;
    bool tmcl = true;
    bool axis = true;      // TMCL: axis parameter (GAP) or global (GGP)
    uint8_t number = 0;    // TMCL parameter number
    uint8_t motor_bank = 0;  // TMCL: motor for GAP, bank for GGP
    uint16_t index = 0;    // CANopen
    uint8_t sub = 0;
    Json echo;             // the item as the request gave it
  };

  void send(const Json& message) { connection_.send_text(message.dump()); }

  // Counts a request until its reply; `reply` runs only while the session lives.
  template <class Answer>
  std::function<void(const Answer&)> replying(std::function<void(Session&, const Answer&)> reply) {
    ++pending_;
    return [link = link_, reply = std::move(reply)](const Answer& answer) {
      if (link->session == nullptr) return;
      --link->session->pending_;
      reply(*link->session, answer);
    };
  }

  void reply_list(const Json& id) {
    Json modules = Json::array();
    for (size_t i = 0; i < console_.targets().size(); ++i) {
      const ConsoleTarget& target = console_.targets()[i];
      Json module = {{"module", i},
                     {"name", target.name},
                     {"type", target.module},
                     {"product", target.product_name},
                     {"firmware", target.firmware},
                     {"protocol", console_.port(i) != nullptr ? "tmcl" : target.canopen_node_id ? "canopen" : "none"},
                     {"motors", target.motor_count},
                     {"sections", listing_json(target)}};
      if (target.tmcl == nullptr && target.tmcl_can != nullptr && console_.port(i) != nullptr) {
        const tmcl::CanSettings ids = target.tmcl_can->settings();
        module["tmcl_can"] = {{"receive_id", ids.receive_id}, {"send_id", ids.send_id}};
      }
      if (target.canopen_node_id) {
        module["node_id"] = *target.canopen_node_id;
        if (console_.sdo() != nullptr) {
          if (const std::optional<uint8_t> state = console_.sdo()->announced_state(*target.canopen_node_id)) {
            module["nmt_state"] = std::string(nmt_state_name(*state));
          }
        }
      }
      modules.push_back(std::move(module));
    }
    send(Json{{"id", id}, {"ok", true}, {"modules", std::move(modules)}, {"sim_time_us", console_.sim_time_us()}});
  }

  // {"op":"nmt_state"}: the NMT state of each CANopen node, as `list` has it, without the tables
  // (a page that follows the state asks for this, not for the whole `list`).
  void reply_nmt_state(const Json& id) {
    Json nodes = Json::array();
    for (size_t i = 0; i < console_.targets().size(); ++i) {
      const ConsoleTarget& target = console_.targets()[i];
      if (!target.canopen_node_id) continue;
      Json node = {{"module", i}, {"node_id", *target.canopen_node_id}};
      if (console_.sdo() != nullptr) {
        if (const std::optional<uint8_t> state = console_.sdo()->announced_state(*target.canopen_node_id)) {
          node["nmt_state"] = std::string(nmt_state_name(*state));
        }
      }
      nodes.push_back(std::move(node));
    }
    send(Json{{"id", id}, {"ok", true}, {"nodes", std::move(nodes)}, {"sim_time_us", console_.sim_time_us()}});
  }

  // An item from a request's fields, or why not.
  std::optional<Item> item_of(const Json& request, std::string& error) {
    Item item;
    const ConsoleTarget* target = console_.target_of(request, item.module, error);
    if (target == nullptr) return std::nullopt;
    item.echo = Json::object();
    item.echo["module"] = item.module;
    if (console_.port(item.module) != nullptr) {
      const auto kind = request.find("kind");
      const std::string kind_text = kind != request.end() && kind->is_string() ? kind->get<std::string>() : "axis";
      if (kind_text != "axis" && kind_text != "global") {
        error = "\"kind\": expected \"axis\" or \"global\"";
        return std::nullopt;
      }
      item.axis = kind_text == "axis";
      const std::optional<int64_t> number = integer_field(request, "number");
      const std::optional<int64_t> motor_bank = integer_field(request, item.axis ? "axis" : "bank");
      if (!number || *number < 0 || *number > 255) {
        error = "\"number\": expected a parameter number 0..255";
        return std::nullopt;
      }
      if (request.contains(item.axis ? "axis" : "bank") && (!motor_bank || *motor_bank < 0 || *motor_bank > 255)) {
        error = std::string("\"") + (item.axis ? "axis" : "bank") + "\": expected 0..255";
        return std::nullopt;
      }
      item.number = static_cast<uint8_t>(*number);
      item.motor_bank = static_cast<uint8_t>(motor_bank.value_or(0));
      if (item.axis && item.motor_bank >= target->motor_count) {
        error = motor_error(*target, item.motor_bank);
        return std::nullopt;
      }
      item.echo["kind"] = kind_text;
      item.echo["number"] = item.number;
      item.echo[item.axis ? "axis" : "bank"] = item.motor_bank;
      return item;
    }
    if (target->canopen_node_id && console_.sdo() != nullptr) {
      item.tmcl = false;
      const std::optional<int64_t> index = integer_field(request, "index");
      const std::optional<int64_t> sub = integer_field(request, "sub");
      if (!index || *index < 0 || *index > 0xFFFF) {
        error = "\"index\": expected an object index 0..65535";
        return std::nullopt;
      }
      if (request.contains("sub") && (!sub || *sub < 0 || *sub > 255)) {
        error = "\"sub\": expected a sub-index 0..255";
        return std::nullopt;
      }
      item.index = static_cast<uint16_t>(*index);
      item.sub = static_cast<uint8_t>(sub.value_or(0));
      item.echo["index"] = item.index;
      item.echo["sub"] = item.sub;
      return item;
    }
    error = "module " + std::to_string(item.module) + " (" + target->name + ") cannot be reached from the console";
    return std::nullopt;
  }

  static Json tmcl_reply_json(const Json& id, const TmclAnswer& answer) {
    if (!answer.error.empty()) return Json{{"id", id}, {"ok", false}, {"error", answer.error}};
    if (!answer.replied) return Json{{"id", id}, {"ok", true}, {"replied", false}};
    Json reply = {{"id", id},
                  {"ok", tmcl::is_success(answer.status)},
                  {"status", answer.status},
                  {"status_name", tmcl::status_name(answer.status)},
                  {"command", answer.command},
                  {"value", answer.value}};
    if (answer.version) {
      reply = {{"id", id}, {"ok", true}, {"version", *answer.version}};
    }
    return reply;
  }

  Json sdo_reply_json(const Json& id, const SdoAnswer& answer, const Item& item) const {
    if (!answer.answered) return Json{{"id", id}, {"ok", false}, {"error", answer.error}};
    if (answer.abort_code != 0) {
      return Json{{"id", id},
                  {"ok", false},
                  {"abort", abort_text(answer.abort_code)},
                  {"abort_code", answer.abort_code},
                  {"abort_text", canopen::describe(answer.abort_code)}};
    }
    Json reply = {{"id", id}, {"ok", true}};
    if (!answer.data.empty()) add_value(reply, answer.data, item);
    return reply;
  }

  // "value" as the object's type reads it (a number, or "text" for a string) and the raw "data".
  void add_value(Json& out, const std::vector<uint8_t>& data, const Item& item) const {
    out["data"] = hex_text(data);
    const host::DictionaryEntry* entry = console_.entry(console_.targets()[item.module], item.index, item.sub);
    if (entry != nullptr && entry->info.type == canopen::DataType::kVisibleString) {
      out["text"] = std::string(data.begin(), data.end());
      return;
    }
    if (data.size() > 4) return;
    uint32_t raw = 0;
    for (size_t i = 0; i < data.size(); ++i) raw |= static_cast<uint32_t>(data[i]) << (8 * i);
    int64_t value = raw;
    if (entry != nullptr) {
      const canopen::DataType type = entry->info.type;
      if (type == canopen::DataType::kInteger8) value = static_cast<int8_t>(raw);
      if (type == canopen::DataType::kInteger16) value = static_cast<int16_t>(raw);
      if (type == canopen::DataType::kInteger32) value = static_cast<int32_t>(raw);
    }
    out["value"] = value;
  }

  // get/set/store/restore of a parameter (TMCL) or an object (CANopen).
  std::string parameter_op(const std::string& op, const Json& request, const Json& id) {
    std::string error;
    std::optional<Item> item = item_of(request, error);
    if (!item) return error;
    std::optional<int64_t> value;
    if (op == "set") {
      value = integer_field(request, "value");
      if (!value) return "\"value\": expected an integer";
    }
    if (item->tmcl) {
      if (value && (*value < std::numeric_limits<int32_t>::min() || *value > std::numeric_limits<uint32_t>::max())) {
        return "\"value\": does not fit the 32 bits of a TMCL value";
      }
      tmcl::Instruction instruction;
      namespace cmd = tmcl::command;
      const std::map<std::string, std::pair<uint8_t, uint8_t>> commands = {{"get", {cmd::kGap, cmd::kGgp}},
                                                                          {"set", {cmd::kSap, cmd::kSgp}},
                                                                          {"store", {cmd::kStap, cmd::kStgp}},
                                                                          {"restore", {cmd::kRsap, cmd::kRsgp}}};
      const auto& [axis_command, global_command] = commands.at(op);
      instruction.command = item->axis ? axis_command : global_command;
      instruction.type = item->number;
      instruction.motor_bank = item->motor_bank;
      instruction.value = static_cast<int32_t>(static_cast<uint32_t>(value.value_or(0)));
      console_.port(item->module)->request(
          instruction, replying<TmclAnswer>([id](Session& session, const TmclAnswer& answer) {
            session.send(tmcl_reply_json(id, answer));
          }));
      return {};
    }
    SdoMaster* sdo = console_.sdo();
    const uint8_t node = *console_.targets()[item->module].canopen_node_id;
    std::vector<uint8_t> data;
    uint16_t index = item->index;
    uint8_t sub = item->sub;
    if (op == "set") {
      const host::DictionaryEntry* entry = console_.entry(console_.targets()[item->module], item->index, item->sub);
      size_t size = entry != nullptr ? canopen::type_size(entry->info.type) : 0;
      if (const std::optional<int64_t> given = integer_field(request, "size")) size = static_cast<size_t>(*given);
      if (size < 1 || size > 4) {
        return "\"size\": give the object's size in bytes (1..4); the console knows no numeric type for this object";
      }
      const int64_t low = -(int64_t{1} << (8 * size - 1));
      const int64_t high = (int64_t{1} << (8 * size)) - 1;
      if (*value < low || *value > high) return "\"value\": does not fit the object's " + std::to_string(size) + " bytes";
      data.resize(size);
      for (size_t i = 0; i < size; ++i) data[i] = static_cast<uint8_t>(static_cast<uint64_t>(*value) >> (8 * i));
    } else if (op == "store" || op == "restore") {
      // CiA-301 1010/1011: "save" / "load" written to a sub-index (1: everything, the default).
      index = op == "store" ? 0x1010 : 0x1011;
      sub = request.contains("sub") ? item->sub : 1;
      data = op == "store" ? std::vector<uint8_t>{'s', 'a', 'v', 'e'} : std::vector<uint8_t>{'l', 'o', 'a', 'd'};
    }
    auto reply = replying<SdoAnswer>([id, item = *item](Session& session, const SdoAnswer& answer) {
      session.send(session.sdo_reply_json(id, answer, item));
    });
    if (op == "get") {
      sdo->upload(node, index, sub, std::move(reply));
    } else {
      sdo->download(node, index, sub, std::move(data), std::move(reply));
    }
    return {};
  }

  // {"op":"sdo_read"|"sdo_write","module":N,"index":I,"sub":S[,"value":V,"size":B | "data":"HEX"]} or
  // with "node": N instead of a module, any node on the bus.
  std::string sdo_op(bool write, const Json& request, const Json& id) {
    SdoMaster* sdo = console_.sdo();
    if (sdo == nullptr) return "no CAN bus on this serve";
    if (!request.contains("node")) {
      if (write && request.contains("value")) return parameter_op("set", request, id);
      if (!write) return parameter_op("get", request, id);
    }
    uint8_t node = 0;
    Item item;
    item.tmcl = false;
    if (const std::optional<int64_t> given = integer_field(request, "node")) {
      if (*given < 1 || *given > 127) return "\"node\": expected a node ID 1..127";
      node = static_cast<uint8_t>(*given);
      // The dictionary of a listed module with this node ID types the value.
      for (size_t i = 0; i < console_.targets().size(); ++i) {
        if (console_.targets()[i].canopen_node_id == node) item.module = i;
      }
    } else {
      std::string error;
      const ConsoleTarget* target = console_.target_of(request, item.module, error);
      if (target == nullptr) return error;
      if (!target->canopen_node_id) return "module " + target->name + " is not a CANopen node";
      node = *target->canopen_node_id;
    }
    const std::optional<int64_t> index = integer_field(request, "index");
    const std::optional<int64_t> sub = integer_field(request, "sub");
    if (!index || *index < 0 || *index > 0xFFFF) return "\"index\": expected an object index 0..65535";
    if (!sub || *sub < 0 || *sub > 255) return "\"sub\": expected a sub-index 0..255";
    item.index = static_cast<uint16_t>(*index);
    item.sub = static_cast<uint8_t>(*sub);
    std::vector<uint8_t> data;
    if (write) {
      if (const std::optional<int64_t> value = integer_field(request, "value")) {
        const std::optional<int64_t> size = integer_field(request, "size");
        if (!size || *size < 1 || *size > 4) return "\"size\": expected 1..4 bytes with \"value\"";
        data.resize(static_cast<size_t>(*size));
        for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<uint8_t>(static_cast<uint64_t>(*value) >> (8 * i));
      } else {
        const auto hex = request.find("data");
        if (hex == request.end() || !hex->is_string()) return "\"value\" and \"size\", or \"data\": hex bytes, expected";
        const std::string text = hex->get<std::string>();
        if (text.empty() || text.size() % 2 != 0 || text.size() > 8) return "\"data\": expected 1..4 bytes in hex";
        for (size_t i = 0; i < text.size(); i += 2) {
          const std::optional<int64_t> byte = parse_integer("0x" + text.substr(i, 2));
          if (!byte) return "\"data\": expected hex digits";
          data.push_back(static_cast<uint8_t>(*byte));
        }
      }
    }
    auto reply = replying<SdoAnswer>([id, item](Session& session, const SdoAnswer& answer) {
      session.send(session.sdo_reply_json(id, answer, item));
    });
    if (write) {
      sdo->download(node, item.index, item.sub, std::move(data), std::move(reply));
    } else {
      sdo->upload(node, item.index, item.sub, std::move(reply));
    }
    return {};
  }

  // {"op":"nmt","module":N | "node":N (0: all),"command":"start"|"stop"|"pre-operational"|"reset-node"|"reset-communication"}
  std::string nmt_op(const Json& request, const Json& id) {
    SdoMaster* sdo = console_.sdo();
    if (sdo == nullptr) return "no CAN bus on this serve";
    static const std::map<std::string, uint8_t> kCommands = {{"start", 0x01},
                                                            {"stop", 0x02},
                                                            {"pre-operational", 0x80},
                                                            {"reset-node", 0x81},
                                                            {"reset-communication", 0x82}};
    const auto command = request.find("command");
    if (command == request.end() || !command->is_string() || !kCommands.contains(command->get<std::string>())) {
      return "\"command\": expected start, stop, pre-operational, reset-node or reset-communication";
    }
    uint8_t node = 0;
    if (request.contains("node")) {
      const std::optional<int64_t> given = integer_field(request, "node");
      if (!given || *given < 0 || *given > 127) return "\"node\": expected 0 (all) or a node ID 1..127";
      node = static_cast<uint8_t>(*given);
    } else {
      std::string error;
      size_t index = 0;
      const ConsoleTarget* target = console_.target_of(request, index, error);
      if (target == nullptr) return error;
      if (!target->canopen_node_id) return "module " + target->name + " is not a CANopen node";
      node = *target->canopen_node_id;
    }
    sdo->nmt(kCommands.at(command->get<std::string>()), node);
    send(Json{{"id", id}, {"ok", true}, {"node", node}});
    return {};
  }

  // The Program view's ops (web_program.h) on a TMCL module.
  std::string program_op(const std::string& name, const Json& request, const Json& id) {
    std::string error;
    size_t index = 0;
    const ConsoleTarget* target = console_.target_of(request, index, error);
    if (target == nullptr) return error;
    if (console_.port(index) == nullptr) return "module " + target->name + " takes no TMCL from the console";
    auto reply = replying<Json>([](Session& session, const Json& message) { session.send(message); });
    error = start_program_op(name, request, id, *console_.port(index), std::move(reply));
    if (!error.empty()) --pending_;  // no reply will come through `reply`
    return error;
  }

  // {"op":"tmcl","module":N,"text":"MVP ABS, 0, 1000"}: one instruction as `motwin tmcl` takes it.
  std::string tmcl_op(const Json& request, const Json& id) {
    std::string error;
    size_t index = 0;
    const ConsoleTarget* target = console_.target_of(request, index, error);
    if (target == nullptr) return error;
    if (console_.port(index) == nullptr) return "module " + target->name + " takes no TMCL from the console";
    const auto text = request.find("text");
    if (text == request.end() || !text->is_string()) return "\"text\": expected an instruction such as \"GAP 1, 0\"";
    const Result<tmcl::Instruction> instruction = parse_instruction(text->get<std::string>());
    if (!instruction) return instruction.error();
    // The console's channel is a binary one; ASCII mode would leave it unable to read replies.
    if (instruction->command == tmcl::command::kEnterAsciiMode) return "command 139 (ASCII mode) is for a serial line";
    console_.port(index)->request(*instruction,
                                  replying<TmclAnswer>([id, instruction = *instruction](Session& session,
                                                                                        const TmclAnswer& answer) {
                                    Json reply = tmcl_reply_json(id, answer);
                                    reply["instruction"] = format_instruction(instruction);
                                    session.send(reply);
                                  }));
    return {};
  }

  // {"op":"datalogger","module":N,"action":...}: the module's datalogger through its TMCL
  // service (tools/web/web_datalogger.h).
  std::string datalogger_op(const Json& request, const Json& id) {
    std::string error;
    size_t index = 0;
    const ConsoleTarget* target = console_.target_of(request, index, error);
    if (target == nullptr) return error;
    if (console_.port(index) == nullptr) return "module " + target->name + " takes no TMCL from the console: no datalogger";
    std::variant<DataloggerPlan, std::string> plan = parse_datalogger_request(request);
    if (const std::string* refused = std::get_if<std::string>(&plan)) return *refused;
    for (const DataloggerChannel& channel : std::get<DataloggerPlan>(plan).channels) {
      if (channel.axis && channel.motor_bank >= target->motor_count) return motor_error(*target, channel.motor_bank);
    }
    TmclRequests* port = console_.port(index);
    DataloggerLink link;
    link.request = [port](const tmcl::Instruction& instruction, std::function<void(const DataloggerAnswer&)> done) {
      port->request(instruction, [done = std::move(done)](const TmclAnswer& answer) {
        done(DataloggerAnswer{answer.replied, answer.status, answer.value});
      });
    };
    link.alive = [session_link = link_] { return session_link->session != nullptr; };
    link.sim_time_us = [&console = console_] { return console.sim_time_us(); };
    run_datalogger(std::get<DataloggerPlan>(plan), std::move(link),
                   replying<Json>([id](Session& session, const Json& answer) {
                     Json reply = answer;
                     reply["id"] = id;
                     session.send(reply);
                   }));
    return {};
  }

  // {"op":"subscribe","items":[{"module":0,"kind":"axis","number":1,"axis":0}, {"module":1,"index":24676}],
  //  "rate_hz":25}: an "update" push of every item's value rate_hz times a second (wall time), each
  // batch stamped with the simulated time; replaces the session's earlier subscription.
  std::string subscribe_op(const Json& request, const Json& id) {
    const auto items = request.find("items");
    if (items == request.end() || !items->is_array()) return "\"items\": expected an array";
    if (items->size() > kMaxSubscribedItems) return "at most " + std::to_string(kMaxSubscribedItems) + " items";
    const auto rate = request.find("rate_hz");
    const double rate_hz = rate != request.end() && rate->is_number() ? rate->get<double>() : 10.0;
    if (!(rate_hz > 0) || rate_hz > kMaxUpdateRateHz) return "\"rate_hz\": expected more than 0 and at most 100";
    std::vector<Item> subscribed;
    for (const Json& given : *items) {
      if (!given.is_object()) return "\"items\": each an object";
      std::string error;
      std::optional<Item> item = item_of(given, error);
      if (!item) return error;
      subscribed.push_back(std::move(*item));
    }
    stop_subscription();
    subscribed_ = std::move(subscribed);
    period_us_ = static_cast<uint64_t>(1e6 / rate_hz);
    send(Json{{"id", id}, {"ok", true}, {"items", subscribed_.size()}, {"rate_hz", rate_hz}});
    if (!subscribed_.empty()) schedule_batch(host::monotonic_now_us());
    return {};
  }

  void stop_subscription() {
    if (timer_) console_.loop().cancel_timer(*timer_);
    timer_.reset();
    subscribed_.clear();
    ++generation_;
  }

  void schedule_batch(uint64_t due_us) {
    timer_ = console_.loop().add_timer_at(due_us, [this] {
      timer_.reset();
      // Batches follow the wall clock; one that is still being read makes the next one wait
      // (the page gets fewer, never stale-queued, updates). One due before the simulation moved
      // on (a late timer, then the next multiple of the period a moment later, or a loaded
      // machine) is skipped: a page plots against simulated time, which must increase.
      if (!batch_in_flight_ && console_.sim_time_us() != last_batch_sim_time_us_) start_batch();
      // The next batch at the next multiple of the period on the wall clock: sessions of the same
      // rate (or of rates that divide each other) start their batches in the same moment, so
      // that their reads of the same items are shared (TmclPort::shared_read).
      const uint64_t now = host::monotonic_now_us();
      schedule_batch((now / period_us_ + 1) * period_us_);
    });
  }

  struct Batch {
    uint64_t sim_time_us;
    Json values;
    size_t left;
    uint64_t generation;
  };

  void start_batch() {
    batch_in_flight_ = true;
    last_batch_sim_time_us_ = console_.sim_time_us();
    auto batch = std::make_shared<Batch>(Batch{last_batch_sim_time_us_, Json::array(), subscribed_.size(), generation_});
    for (size_t i = 0; i < subscribed_.size(); ++i) batch->values.push_back(subscribed_[i].echo);
    for (size_t i = 0; i < subscribed_.size(); ++i) {
      const Item& item = subscribed_[i];
      const auto finish_one = [link = link_, batch, i](auto fill) {
        Session* session = link->session;
        if (session == nullptr) return;
        fill(batch->values[i]);
        if (--batch->left == 0) session->finish_batch(*batch);
      };
      if (item.tmcl) {
        tmcl::Instruction instruction;
        instruction.command = item.axis ? tmcl::command::kGap : tmcl::command::kGgp;
        instruction.type = item.number;
        instruction.motor_bank = item.motor_bank;
        console_.port(item.module)->shared_read(instruction, [finish_one](const TmclAnswer& answer) {
          finish_one([&answer](Json& value) {
            if (!answer.error.empty()) {
              value["error"] = answer.error;
              return;
            }
            value["status"] = answer.status;
            if (tmcl::is_success(answer.status)) value["value"] = answer.value;
          });
        });
      } else {
        console_.sdo()->shared_upload(*console_.targets()[item.module].canopen_node_id, item.index, item.sub,
                                      [finish_one, item, link = link_](const SdoAnswer& answer) {
                                        finish_one([&](Json& value) {
                                          if (!answer.answered) {
                                            value["error"] = answer.error;
                                          } else if (answer.abort_code != 0) {
                                            value["abort"] = abort_text(answer.abort_code);
                                          } else if (link->session != nullptr) {
                                            link->session->add_value(value, answer.data, item);
                                          }
                                        });
                                      });
      }
    }
  }

  void finish_batch(const Batch& batch) {
    batch_in_flight_ = false;
    if (batch.generation != generation_) return;
    connection_.send_latest(
        Json{{"push", "update"}, {"sim_time_us", batch.sim_time_us}, {"values", batch.values}}.dump());
  }

  // "world" and "world_set" (tools/web/world_ops.h) on the module the request names.
  std::string world_request(const std::string& op, const Json& request, const Json& id) {
    std::string error;
    size_t index = 0;
    const ConsoleTarget* target = console_.target_of(request, index, error);
    if (target == nullptr) return error;
    Result<Json> reply = world_op(op, request, index, target->world, console_.sim_time_us());
    if (!reply) return reply.error();
    reply->emplace("id", id);
    send(*reply);
    return {};
  }

  // {"op":"monitor","enable":true|false}: "frames" pushes of the bus's frames, or none.
  std::string monitor_op(const Json& request, const Json& id) {
    if (console_.sdo() == nullptr) return "no CAN bus on this serve";
    const auto enable = request.find("enable");
    if (enable != request.end() && !enable->is_boolean()) return "\"enable\": expected true or false";
    const bool on = enable == request.end() || enable->get<bool>();
    stop_monitor();
    send(Json{{"id", id}, {"ok", true}, {"enable", on}});
    if (on) {
      monitoring_ = true;
      schedule_monitor_push(host::monotonic_now_us() + kMonitorPeriodUs);
    }
    return {};
  }

 public:
  void on_bus_frame(const can::CanFrame& frame, uint64_t timestamp_us) {
    if (!monitoring_) return;
    if (monitored_.size() >= kMaxMonitorBufferedFrames) {
      ++monitor_dropped_;  // a slow page: the newest frames go, counted; the buffer stays bounded
      return;
    }
    monitored_.push_back(MonitoredFrame{frame, timestamp_us});
  }

 private:
  struct MonitoredFrame {
    can::CanFrame frame;
    uint64_t timestamp_us;
  };

  void stop_monitor() {
    if (monitor_timer_) console_.loop().cancel_timer(*monitor_timer_);
    monitor_timer_.reset();
    monitoring_ = false;
    monitored_.clear();
    monitor_dropped_ = 0;
  }

  void schedule_monitor_push(uint64_t due_us) {
    monitor_timer_ = console_.loop().add_timer_at(due_us, [this] {
      monitor_timer_.reset();
      push_frames();
      schedule_monitor_push(host::monotonic_now_us() + kMonitorPeriodUs);
    });
  }

  // One push of the oldest frames, unless the page has not read what was sent before: then they
  // wait in the bounded buffer.
  void push_frames() {
    if (monitored_.empty() && monitor_dropped_ == monitor_dropped_sent_) return;
    if (connection_.queued_bytes() > kMonitorMaxQueuedBytes) return;
    Json frames = Json::array();
    const size_t count = std::min(monitored_.size(), kMaxFramesPerMonitorPush);
    for (size_t i = 0; i < count; ++i) {
      const MonitoredFrame& monitored = monitored_.front();
      const uint8_t* data = monitored.frame.data;
      const std::vector<uint8_t> bytes(data, data + std::min<size_t>(monitored.frame.dlc, 8));
      Json frame = {{"t_us", monitored.timestamp_us}, {"id", monitored.frame.id}, {"data", hex_text(bytes)}};
      if (monitored.frame.rtr) frame["rtr"] = true;
      if (monitored.frame.extended) frame["extended"] = true;
      frames.push_back(std::move(frame));
      monitored_.pop_front();
    }
    monitor_dropped_sent_ = monitor_dropped_;
    connection_.send_text(
        Json{{"push", "frames"}, {"frames", std::move(frames)}, {"dropped", monitor_dropped_}}.dump());
  }

  Impl& console_;
  host::web::WebConnection& connection_;
  std::shared_ptr<SessionLink> link_;
  bool monitoring_ = false;
  std::deque<MonitoredFrame> monitored_;
  uint64_t monitor_dropped_ = 0;
  uint64_t monitor_dropped_sent_ = 0;
  std::optional<host::EventLoop::TimerId> monitor_timer_;
  size_t pending_ = 0;
  std::vector<Item> subscribed_;
  uint64_t period_us_ = 100'000;
  uint64_t last_batch_sim_time_us_ = UINT64_MAX;  // none yet
  std::optional<host::EventLoop::TimerId> timer_;
  bool batch_in_flight_ = false;
  uint64_t generation_ = 0;
};

void WebConsole::Impl::broadcast_event(size_t index, const TmclAnswer& answer) {
  for (Session* session : sessions_) session->send_event(index, answer);
}

void WebConsole::Impl::broadcast_frame(const can::CanFrame& frame, uint64_t timestamp_us) {
  for (Session* session : sessions_) session->on_bus_frame(frame, timestamp_us);
}

WebConsole::WebConsole(host::EventLoop& loop, std::function<uint64_t()> sim_time_us, std::vector<ConsoleTarget> targets,
                       host::CanBus* bus)
    : impl_(std::make_unique<Impl>(loop, std::move(sim_time_us), std::move(targets), bus)) {}

WebConsole::~WebConsole() = default;

std::unique_ptr<host::web::WebSessionHandler> WebConsole::open_session(host::web::WebConnection& connection) {
  return std::make_unique<Impl::Session>(*impl_, connection);
}

const std::vector<ConsoleTarget>& WebConsole::targets() const { return impl_->targets(); }

}  // namespace motwin::tools::web
