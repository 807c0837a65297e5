#include "tools/web/tmcl_can_port.h"

#include <string>
#include <utility>

#include "core/tmcl/status.h"

namespace motwin::tools::web {

TmclCanPort::TmclCanPort(host::CanBus& bus, host::EventLoop& loop, Settings settings, EventListener on_event)
    : bus_(bus), loop_(loop), settings_(std::move(settings)), on_event_(std::move(on_event)) {
  id_ = bus_.attach(*this);
}

TmclCanPort::~TmclCanPort() {
  *alive_ = false;
  if (timer_) loop_.cancel_timer(*timer_);
  bus_.detach(id_);
}

void TmclCanPort::request(const tmcl::Instruction& instruction, Done done) {
  (held_ ? held_back_ : waiting_).push_back(Pending{instruction, std::move(done)});
  send_next();
}

bool TmclCanPort::hold() { return !std::exchange(held_, true); }

void TmclCanPort::held_request(const tmcl::Instruction& instruction, Done done) {
  waiting_.push_back(Pending{instruction, std::move(done)});
  send_next();
}

void TmclCanPort::release() {
  held_ = false;
  while (!held_back_.empty()) {
    waiting_.push_back(std::move(held_back_.front()));
    held_back_.pop_front();
  }
  send_next();
}

void TmclCanPort::send_next() {
  // The module answers inside the bus delivery, so bus_.send() may come back through on_frame()
  // and finish(); the loop here sends what that made ready instead of recursing.
  if (sending_) return;
  sending_ = true;
  while (!in_flight_ && !waiting_.empty()) {
    in_flight_ = std::move(waiting_.front());
    waiting_.pop_front();
    in_flight_ids_ = settings_();
    const can::CanFrame frame = tmcl::encode_can_request(in_flight_ids_.receive_id, in_flight_->instruction);
    // Command 137 has no reply (core/tmcl/can_link.h).
    const bool answered = in_flight_->instruction.command != tmcl::command::kRestoreFactoryDefaults;
    if (answered) {
      timer_ = loop_.add_timer_after(kReplyTimeoutUs, [this, alive = alive_] {
        if (!*alive) return;
        timer_.reset();
        TmclAnswer none;
        none.error = "no reply over CAN on ID " + std::to_string(in_flight_ids_.send_id) + " within 1 s";
        finish(std::move(none));
      });
    }
    bus_.send(id_, frame);
    if (!answered && in_flight_) finish(TmclAnswer{});
  }
  sending_ = false;
}

void TmclCanPort::finish(TmclAnswer answer) {
  if (timer_) loop_.cancel_timer(*timer_);
  timer_.reset();
  Pending done = std::move(*in_flight_);
  in_flight_.reset();
  done.done(answer);
  send_next();
}

void TmclCanPort::on_frame(const can::CanFrame& frame, uint64_t /*timestamp_us*/) {
  if (frame.rtr) return;
  // The IDs the request went out with, or the module's IDs now: the reply to SGP 70/71 already
  // uses the new ones (core/tmcl/can_link.cpp).
  const tmcl::CanSettings now = settings_();
  const auto from_module = [&](const tmcl::CanSettings& ids) {
    return frame.id == ids.send_id && (frame.dlc == 8 || frame.data[0] == (ids.receive_id & 0xFF));
  };
  const bool ours = from_module(now) || (in_flight_ && from_module(in_flight_ids_));
  if (!ours) return;
  const bool version_asked = in_flight_ && in_flight_->instruction.command == tmcl::command::kGetFirmwareVersion &&
                             in_flight_->instruction.type == 0;
  TmclAnswer answer;
  answer.replied = true;
  if (version_asked && frame.dlc == 8) {
    // The 8 version characters are the whole data (core/tmcl/can_link.h).
    answer.status = tmcl::to_byte(tmcl::Status::kOk);
    answer.command = tmcl::command::kGetFirmwareVersion;
    answer.version = std::string(frame.data, frame.data + 8);
    return finish(std::move(answer));
  }
  if (frame.dlc < tmcl::kCanRequestLength) return;
  if (frame.data[0] != (now.receive_id & 0xFF) && !(in_flight_ && frame.data[0] == (in_flight_ids_.receive_id & 0xFF))) {
    return;
  }
  answer.status = frame.data[1];
  answer.command = frame.data[2];
  answer.value = static_cast<int32_t>(static_cast<uint32_t>(frame.data[3]) << 24 |
                                      static_cast<uint32_t>(frame.data[4]) << 16 |
                                      static_cast<uint32_t>(frame.data[5]) << 8 | frame.data[6]);
  // A delayed reply of command 138 (target reached) comes whenever it is due. Without a request
  // on the bus, a reply is another CAN host's.
  if (answer.status == tmcl::to_byte(tmcl::Status::kPositionReachedEvent)) {
    if (on_event_) on_event_(answer);
    return;
  }
  if (in_flight_) finish(std::move(answer));
}

}  // namespace motwin::tools::web
