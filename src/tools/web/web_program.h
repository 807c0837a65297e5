// The web console's program ops (docs/web-console.md "Protocol"), for the Program view of a TMCL
// module: the stored program read back with 134 and disassembled, the application status (135),
// run / stop / step / reset (129, 128, 130, 131), and a source assembled and downloaded (132,
// the instructions, NOP, 133) then verified with 134, as `motwin download` does. Every request
// goes through the module's TMCL service (web_tmcl.h), so the page can do nothing a TMCL host
// could not. The requests and their checks are those of tools/program_transfer.h, the text that
// of tools/tmcl_disassembler.h, the assembler tools/tmcl_assembler.h.
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "tools/web/web_tmcl.h"

namespace motwin::tools::web {

inline constexpr std::string_view kProgramOpNames = "program_read, program_download, program_control, app_status";

bool is_program_op(std::string_view op);

// Starts `op` (one of kProgramOpNames) for `request` with the reply id `id`. Returns an error
// text for a request that cannot start (a missing or bad field), and then `reply` is never
// called; otherwise `reply` runs exactly once, with the reply, when the module has answered.
// A download that has started finishes (up to 133) even when nobody waits for its reply.
std::string start_program_op(std::string_view op, const nlohmann::json& request, const nlohmann::json& id,
                             TmclRequests& module, std::function<void(const nlohmann::json&)> reply);

}  // namespace motwin::tools::web
