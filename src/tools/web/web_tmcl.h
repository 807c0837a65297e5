// How the web console's ops reach a TMCL module: its requests as a host's, either 9-byte frames
// through the module's own TMCL service (the console's TmclPort, web_console.cpp) or TMCL over
// CAN frames on serve's virtual bus (TmclCanPort, tmcl_can_port.h). The ops see only this
// interface.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "core/tmcl/instruction.h"

namespace motwin::tools::web {

struct TmclAnswer {
  bool replied = false;  // false: the module sends no reply to this command (137, another address)
  uint8_t status = 0;
  uint8_t command = 0;
  int32_t value = 0;
  std::optional<std::string> version;  // command 136 type 0
  std::string error;                   // set: no answer came (TMCL over CAN: a timeout)
};

class TmclRequests {
 public:
  using Done = std::function<void(const TmclAnswer&)>;

  // Sends `instruction`; `done` runs with the reply. Replies come in the order of the requests.
  virtual void request(const tmcl::Instruction& instruction, Done done) = 0;
  // A read of a subscribed value, which a port may answer from the same read another session
  // asked for and is still waiting (web_console.cpp's TmclPort); by default a request of its own.
  virtual void shared_read(const tmcl::Instruction& instruction, Done done) { request(instruction, std::move(done)); }

  // A download stores every non-control command the module receives (docs/tmcl-programs.md
  // "Program memory and download"), so the console's other requests (a page's live values)
  // must not reach the module during one: after hold() only requests made with
  // `held_request` go out; the others wait, in order, until release(). hold() fails (false)
  // while another holder has it.
  virtual bool hold() = 0;
  virtual void held_request(const tmcl::Instruction& instruction, Done done) = 0;
  virtual void release() = 0;

  virtual ~TmclRequests() = default;
};

}  // namespace motwin::tools::web
