#include "tools/web/web_program.h"
#include "tools/web/web_json.h"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/tmcl/interpreter.h"
#include "core/tmcl/status.h"
#include "tools/program_transfer.h"
#include "tools/tmcl_assembler.h"
#include "tools/tmcl_disassembler.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::tools::web {
namespace {

using Json = nlohmann::json;
using Reply = std::function<void(const Json&)>;
namespace cmd = tmcl::command;

constexpr uint8_t kOk = tmcl::to_byte(tmcl::Status::kOk);
// Addresses read back per round of requests: 2 requests each, within the 32 requests a
// connection may have queued at the service (docs/host-runtime.md).
constexpr uint32_t kReadBackChunk = 16;
constexpr size_t kMaxMismatchesListed = 10;

// An optional integer field within [low, high]; `error` set when present but not.
std::optional<int64_t> bounded_field(const Json& request, const char* name, int64_t low, int64_t high,
                                     std::string& error) {
  if (!request.contains(name)) return std::nullopt;
  const std::optional<int64_t> value = integer_field(request, name);
  if (!value || *value < low || *value > high) {
    error = fmt::format("\"{}\": expected {}..{}", name, low, high);
    return std::nullopt;
  }
  return value;
}

std::string status_text(uint8_t status) { return fmt::format("status {} ({})", status, tmcl::status_name(status)); }

// The reply fields of one TMCL answer, as the "tmcl" op gives them.
Json answer_reply(const Json& id, const TmclAnswer& answer) {
  if (!answer.replied) return Json{{"id", id}, {"ok", false}, {"error", "the module did not reply"}};
  return Json{{"id", id},
              {"ok", tmcl::is_success(answer.status)},
              {"status", answer.status},
              {"status_name", tmcl::status_name(answer.status)},
              {"command", answer.command},
              {"value", answer.value}};
}

Json instruction_json(const tmcl::Instruction& instruction) {
  return Json{{"command", instruction.command},
              {"type", instruction.type},
              {"motor_bank", instruction.motor_bank},
              {"value", instruction.value},
              {"text", format_instruction(instruction)}};
}

// --- Reading program memory back with 134 ------------------------------------------------------

struct ReadBack {
  std::vector<tmcl::Instruction> instructions;
  std::string end;    // "nop", "memory_end" or "count"
  std::string error;  // set: the read failed here
  std::optional<uint8_t> status;
};

// Reads from `start` on, `count` instructions, or (until_nop) up to the first NOP, which is not
// included, or the end of memory (an "invalid value" status after the first address), as
// read_stored_program does. Requests go out kReadBackChunk addresses at a time.
class ReadBackRun : public std::enable_shared_from_this<ReadBackRun> {
 public:
  using Done = std::function<void(ReadBack)>;

  static void start(TmclRequests& module, uint32_t start, uint32_t count, bool until_nop, Done done) {
    auto run = std::shared_ptr<ReadBackRun>(new ReadBackRun(module, start, count, until_nop, std::move(done)));
    run->next_chunk();
  }

 private:
  ReadBackRun(TmclRequests& module, uint32_t start, uint32_t count, bool until_nop, Done done)
      : module_(module), start_(start), next_(start), end_(start + count), until_nop_(until_nop),
        done_(std::move(done)) {}

  void next_chunk() {
    if (next_ >= end_) return finish(until_nop_ ? "memory_end" : "count");
    const uint32_t first = next_;
    const uint32_t count = std::min(kReadBackChunk, end_ - next_);
    next_ += count;
    auto answers = std::make_shared<std::vector<TmclAnswer>>(2 * count);
    auto left = std::make_shared<size_t>(2 * count);
    for (uint32_t i = 0; i < count; ++i) {
      for (uint8_t type = 0; type < 2; ++type) {
        module_.request(read_back_request(first + i, type),
                        [self = shared_from_this(), answers, left, slot = 2 * i + type, first](const TmclAnswer& answer) {
                          (*answers)[slot] = answer;
                          if (--*left == 0) self->take_chunk(first, *answers);
                        });
      }
    }
  }

  void take_chunk(uint32_t first, const std::vector<TmclAnswer>& answers) {
    for (size_t i = 0; i < answers.size() / 2; ++i) {
      const uint32_t address = first + static_cast<uint32_t>(i);
      for (uint8_t type = 0; type < 2; ++type) {
        const TmclAnswer& answer = answers[2 * i + type];
        if (answer.replied && answer.status == kOk) continue;
        if (until_nop_ && address > start_ && answer.status == tmcl::to_byte(tmcl::Status::kInvalidValue)) {
          return finish("memory_end");  // past the end of program memory
        }
        result_.status = answer.status;
        return fail(answer.replied ? fmt::format("reading address {} (134 type {}): the module answered {}, "
                                                 "expected {}",
                                                 address, type, status_text(answer.status), status_text(kOk))
                                   : fmt::format("reading address {} (134 type {}): no reply", address, type));
      }
      Result<tmcl::Instruction> instruction =
          decode_read_back(address, answers[2 * i].command, answers[2 * i].value, answers[2 * i + 1].value);
      if (!instruction) return fail(instruction.error());
      if (until_nop_ && instruction->command == cmd::kNop) return finish("nop");
      result_.instructions.push_back(*instruction);
    }
    next_chunk();
  }

  void fail(std::string error) {
    result_.error = std::move(error);
    done_(std::move(result_));
  }
  void finish(const char* end) {
    result_.end = end;
    done_(std::move(result_));
  }

  TmclRequests& module_;
  uint32_t start_;
  uint32_t next_;
  uint32_t end_;
  bool until_nop_;
  Done done_;
  ReadBack result_;
};

// {"op":"program_read","module":N[,"count":C]}
std::string program_read(const Json& request, const Json& id, TmclRequests& module, Reply reply) {
  std::string error;
  const uint32_t capacity = static_cast<uint32_t>(kDefaultProgramMemorySize);
  const std::optional<int64_t> count = bounded_field(request, "count", 1, capacity, error);
  if (!error.empty()) return error;
  ReadBackRun::start(module, 0, count ? static_cast<uint32_t>(*count) : capacity, !count,
                     [id, reply = std::move(reply)](ReadBack read) {
                       if (!read.error.empty()) {
                         Json failed = {{"id", id}, {"ok", false}, {"error", read.error}};
                         if (read.status) {
                           failed["status"] = *read.status;
                           failed["status_name"] = tmcl::status_name(*read.status);
                         }
                         return reply(failed);
                       }
                       Json instructions = Json::array();
                       const std::vector<DisassembledLine> lines = disassemble_lines(read.instructions);
                       for (size_t i = 0; i < read.instructions.size(); ++i) {
                         Json line = instruction_json(read.instructions[i]);
                         line["address"] = i;
                         line["text"] = lines[i].text;
                         if (!lines[i].label.empty()) line["label"] = lines[i].label;
                         instructions.push_back(std::move(line));
                       }
                       reply(Json{{"id", id},
                                  {"ok", true},
                                  {"instructions", std::move(instructions)},
                                  {"end", read.end},
                                  {"source", disassemble(read.instructions)}});
                     });
  return {};
}

// --- Application status: 135 types 0..4 -----------------------------------------------------------

const char* mode_name(uint32_t mode) {
  switch (mode) {
    case 0: return "stop";
    case 1: return "run";
    case 2: return "step";
    case 3: return "reset";
    default: return "unknown";
  }
}

// {"op":"app_status","module":N}
std::string app_status(const Json& id, TmclRequests& module, Reply reply) {
  constexpr size_t kTypes = 5;
  auto answers = std::make_shared<std::array<TmclAnswer, kTypes>>();
  auto left = std::make_shared<size_t>(kTypes);
  auto shared_reply = std::make_shared<Reply>(std::move(reply));
  for (uint8_t type = 0; type < kTypes; ++type) {
    module.request({cmd::kGetApplicationStatus, type, 0, 0}, [=](const TmclAnswer& answer) {
      (*answers)[type] = answer;
      if (--*left != 0) return;
      for (uint8_t checked = 0; checked < kTypes; ++checked) {
        const TmclAnswer& got = (*answers)[checked];
        if (!got.replied || got.status != kOk) {
          Json failed = answer_reply(id, got);
          failed["ok"] = false;
          failed["error"] = fmt::format("135 type {}: {}", checked, got.replied ? status_text(got.status) : "no reply");
          return (*shared_reply)(failed);
        }
      }
      const auto& values = *answers;
      const auto status = static_cast<uint32_t>(values[1].value);
      const auto stop = static_cast<uint32_t>(values[4].value);
      const auto reason = static_cast<tmcl::StopReason>(stop >> 16);
      Json out = {{"id", id},
                  {"ok", true},
                  {"mode", status >> 24},
                  {"mode_name", mode_name(status >> 24)},
                  {"waiting", ((status >> 16) & 0xFF) != 0},
                  {"program_counter", status & 0xFFFF},
                  {"download_pointer", static_cast<uint32_t>(values[0].value) & 0xFFFF},
                  {"accumulator", values[2].value},
                  {"x_register", values[3].value},
                  {"stop_reason", stop >> 16},
                  {"stop_reason_name", reason == tmcl::StopReason::kNone ? "none" : tmcl::stop_reason_text(reason)}};
      if (reason != tmcl::StopReason::kNone) out["stop_address"] = stop & 0xFFFF;
      (*shared_reply)(out);
    });
  }
  return {};
}

// --- Run, stop, step, reset -----------------------------------------------------------------------

// {"op":"program_control","module":N,"action":"run"|"continue"|"stop"|"step"|"reset"[,"address":A]}
std::string program_control(const Json& request, const Json& id, TmclRequests& module, Reply reply) {
  const auto action = request.find("action");
  const std::string name = action != request.end() && action->is_string() ? action->get<std::string>() : "";
  std::string error;
  const std::optional<int64_t> address = bounded_field(request, "address", 0, 65535, error);
  if (!error.empty()) return error;
  tmcl::Instruction instruction;
  if (name == "run") {
    // 129 type 1 starts at the address in the value; type 0 continues from the program counter.
    instruction = {cmd::kRunApplication, 1, 0, static_cast<int32_t>(address.value_or(0))};
  } else if (name == "continue") {
    instruction = {cmd::kRunApplication, 0, 0, 0};
  } else if (name == "stop") {
    instruction = {cmd::kStopApplication, 0, 0, 0};
  } else if (name == "step") {
    instruction = {cmd::kStepApplication, 0, 0, 0};
  } else if (name == "reset") {
    instruction = {cmd::kResetApplication, 0, 0, 0};
  } else {
    return "\"action\": expected run, continue, stop, step or reset";
  }
  if (address && name != "run") return "\"address\": only with \"action\": \"run\"";
  module.request(instruction, [id, reply = std::move(reply)](const TmclAnswer& answer) {
    reply(answer_reply(id, answer));
  });
  return {};
}

// --- Assemble, download, verify -------------------------------------------------------------------

// The assembler reads #include files only from the request's "files": the page may not read
// the server's file system.
SourceReader files_reader(std::map<std::string, std::string> files) {
  return [files = std::move(files)](const std::string& path) -> std::optional<std::string> {
    if (const auto found = files.find(path); found != files.end()) return found->second;
    const size_t slash = path.find_last_of('/');
    if (slash != std::string::npos) {
      if (const auto found = files.find(path.substr(slash + 1)); found != files.end()) return found->second;
    }
    return std::nullopt;
  };
}

class DownloadRun : public std::enable_shared_from_this<DownloadRun> {
 public:
  DownloadRun(TmclRequests& module, Json id, Reply reply, std::vector<tmcl::Instruction> instructions, uint32_t start,
              bool verify, Json labels)
      : module_(module), id_(std::move(id)), reply_(std::move(reply)), instructions_(std::move(instructions)),
        steps_(download_steps(instructions_, start)), start_(start), verify_(verify), labels_(std::move(labels)) {}

  // 132 first, alone: were it refused, the instructions would run as direct commands. Then the
  // rest back to back (the service takes them in order); the console's other requests wait.
  void begin() {
    module_.held_request(steps_[0].request, [self = shared_from_this()](const TmclAnswer& answer) {
      if (!self->as_expected(0, answer)) {
        self->module_.release();
        return self->fail(self->step_error(0, answer), answer);
      }
      for (size_t i = 1; i < self->steps_.size(); ++i) {
        self->module_.held_request(self->steps_[i].request,
                                   [self, i](const TmclAnswer& later) { self->take_step(i, later); });
      }
    });
  }

 private:
  bool as_expected(size_t step, const TmclAnswer& answer) const {
    return answer.replied && answer.status == steps_[step].expected_status;
  }
  std::string step_error(size_t step, const TmclAnswer& answer) const {
    if (!answer.replied) return steps_[step].what + ": no reply";
    return fmt::format("{}: the module answered {}, expected {}", steps_[step].what, status_text(answer.status),
                       status_text(steps_[step].expected_status));
  }

  void take_step(size_t step, const TmclAnswer& answer) {
    if (!as_expected(step, answer) && !refused_) refused_ = std::make_pair(step, answer);
    if (step + 1 < steps_.size()) return;
    // 133 answered: download mode is over either way.
    module_.release();
    if (refused_ && refused_->first + 1 < steps_.size()) {
      const bool left = as_expected(step, answer);
      return fail(step_error(refused_->first, refused_->second) +
                      (left ? "; download mode left (133): program memory may hold part of the new program"
                            : "; the module may still be in download mode (133 failed)"),
                  refused_->second);
    }
    if (refused_) return fail(step_error(step, answer), answer);
    if (!verify_) return succeed(false);
    ReadBackRun::start(module_, start_, static_cast<uint32_t>(instructions_.size()), false,
                       [self = shared_from_this()](ReadBack read) { self->compare(read); });
  }

  void compare(const ReadBack& read) {
    if (!read.error.empty()) {
      return reply_(Json{{"id", id_}, {"ok", false}, {"error", "downloaded, but reading it back failed: " + read.error}});
    }
    Json mismatches = Json::array();
    size_t count = 0;
    for (size_t i = 0; i < instructions_.size(); ++i) {
      const tmcl::Instruction& sent = instructions_[i];
      const tmcl::Instruction& held = read.instructions[i];
      if (sent.command == held.command && sent.type == held.type && sent.motor_bank == held.motor_bank &&
          sent.value == held.value) {
        continue;
      }
      if (++count <= kMaxMismatchesListed) {
        mismatches.push_back(
            {{"address", start_ + i}, {"sent", instruction_json(sent)}, {"held", instruction_json(held)}});
      }
    }
    if (count == 0) return succeed(true);
    reply_(Json{{"id", id_},
                {"ok", false},
                {"error", fmt::format("verification failed: {} of {} instructions read back with 134 differ from what "
                                      "was downloaded",
                                      count, instructions_.size())},
                {"mismatches", std::move(mismatches)}});
  }

  void succeed(bool verified) {
    reply_(Json{{"id", id_},
                {"ok", true},
                {"count", instructions_.size()},
                {"start", start_},
                {"verified", verified},
                {"labels", labels_}});
  }
  void fail(const std::string& error, const TmclAnswer& answer) {
    Json failed = {{"id", id_}, {"ok", false}, {"error", error}};
    if (answer.replied) {
      failed["status"] = answer.status;
      failed["status_name"] = tmcl::status_name(answer.status);
    }
    reply_(failed);
  }

  TmclRequests& module_;
  Json id_;
  Reply reply_;
  std::vector<tmcl::Instruction> instructions_;
  std::vector<TransferStep> steps_;
  uint32_t start_;
  bool verify_;
  Json labels_;
  std::optional<std::pair<size_t, TmclAnswer>> refused_;
};

// {"op":"program_download","module":N,"source":"...","file_name":"main.tmc","files":{"lib.tmc":"..."},
//  "start":S,"verify":true}
std::string program_download(const Json& request, const Json& id, TmclRequests& module, Reply reply) {
  const auto source = request.find("source");
  if (source == request.end() || !source->is_string()) return "\"source\": expected the program's text";
  const auto file_name_field = request.find("file_name");
  if (file_name_field != request.end() && (!file_name_field->is_string() || file_name_field->get<std::string>().empty())) {
    return "\"file_name\": expected a file name";
  }
  const std::string file_name = file_name_field != request.end() ? file_name_field->get<std::string>() : "program.tmc";
  std::map<std::string, std::string> files;
  if (const auto given = request.find("files"); given != request.end()) {
    if (!given->is_object()) return "\"files\": expected an object of file names and their text";
    for (const auto& [name, text] : given->items()) {
      if (!text.is_string()) return "\"files\": the text of " + name + " is not a string";
      files[name] = text.get<std::string>();
    }
  }
  std::string error;
  const std::optional<int64_t> start = bounded_field(request, "start", 0, kDefaultProgramMemorySize - 1, error);
  if (!error.empty()) return error;
  const auto verify_field = request.find("verify");
  if (verify_field != request.end() && !verify_field->is_boolean()) return "\"verify\": expected true or false";
  const bool verify = verify_field == request.end() || verify_field->get<bool>();

  AssemblerOptions options;
  options.reader = files_reader(std::move(files));
  options.program_memory_size = kDefaultProgramMemorySize - static_cast<size_t>(start.value_or(0));
  AssemblyResult assembled = assemble_source(source->get<std::string>(), file_name, options);
  if (!assembled.ok()) {
    // An assembly error: nothing reaches the module, as with `motwin download`.
    Json errors = Json::array();
    for (const AssemblyError& failure : assembled.errors) {
      errors.push_back({{"file", failure.location.file},
                        {"line", failure.location.line},
                        {"column", failure.location.column},
                        {"message", failure.message},
                        {"text", format_error(failure)}});
    }
    reply(Json{{"id", id},
               {"ok", false},
               {"error", fmt::format("{} assembly error{}", assembled.errors.size(),
                                     assembled.errors.size() == 1 ? "" : "s")},
               {"errors", std::move(errors)}});
    return {};
  }
  if (!module.hold()) return "a download to this module is in progress";
  Json labels = Json::array();
  for (const SymbolDefinition& symbol : assembled.symbols) {
    if (symbol.kind == SymbolKind::kLabel && !symbol.built_in) {
      labels.push_back({{"name", symbol.name}, {"address", symbol.value}});
    }
  }
  std::make_shared<DownloadRun>(module, id, std::move(reply), std::move(assembled.instructions),
                                static_cast<uint32_t>(start.value_or(0)), verify, std::move(labels))
      ->begin();
  return {};
}

}  // namespace

bool is_program_op(std::string_view op) {
  return op == "program_read" || op == "program_download" || op == "program_control" || op == "app_status";
}

std::string start_program_op(std::string_view op, const Json& request, const Json& id, TmclRequests& module,
                             std::function<void(const Json&)> reply) {
  if (op == "program_read") return program_read(request, id, module, std::move(reply));
  if (op == "app_status") return app_status(id, module, std::move(reply));
  if (op == "program_control") return program_control(request, id, module, std::move(reply));
  if (op == "program_download") return program_download(request, id, module, std::move(reply));
  return "unknown op \"" + std::string(op) + "\"";
}

}  // namespace motwin::tools::web
