#include "host/canopen_sim_module.h"

#include <string>

namespace motwin::host {

void CanopenBusAttachment::attach(CanBus& bus, CanBusEndpoint& node) {
  detach();
  bus_ = &bus;
  id_ = bus.attach(node);
}

void CanopenBusAttachment::detach() {
  if (bus_ != nullptr) bus_->detach(id_);
  bus_ = nullptr;
  id_ = 0;
}

void CanopenBusAttachment::send(const can::CanFrame& frame) {
  if (bus_ != nullptr) bus_->send(id_, frame);
}

board::CanControllerStatus CanopenBusAttachment::controller_status() const {
  board::CanControllerStatus status;
  const CanNodeBusStats* node = bus_ != nullptr ? bus_->node_stats(id_) : nullptr;
  if (node == nullptr) return status;  // on no bus: nothing to go wrong
  const bool bus_off = node->error_state == CanErrorState::kBusOff;
  status.error_state = bus_off ? board::CanErrorState::kBusOff
                       : node->error_state == CanErrorState::kErrorPassive ? board::CanErrorState::kErrorPassive
                                                                             : board::CanErrorState::kErrorActive;
  status.warning = node->warning();
  // The bus counts the times the node went bus-off; all but a bus-off still lasting have ended.
  status.bus_off_recoveries = static_cast<uint32_t>(node->bus_off_count - (bus_off ? 1 : 0));
  return status;
}

Result<canopen::NodeConfig> canopen_node_config(const ModuleOptions& options, uint32_t boot_delay_us,
                                                uint32_t communication_boot_delay_us) {
  if (options.node_id > 127) return Error{"node ID " + std::to_string(options.node_id) + " is out of range (1..127)"};
  canopen::NodeConfig config;
  config.node_id_switches = options.node_id;
  config.serial_number = options.serial_number != 0 ? options.serial_number : 1;
  config.boot_delay_us = options.boot_delay_ms ? *options.boot_delay_ms * 1000u : boot_delay_us;
  config.communication_boot_delay_us =
      options.communication_boot_delay_ms ? *options.communication_boot_delay_ms * 1000u : communication_boot_delay_us;
  return config;
}

}  // namespace motwin::host
