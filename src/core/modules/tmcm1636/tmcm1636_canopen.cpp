#include "core/modules/tmcm1636/tmcm1636_canopen.h"

#include <cmath>

namespace motwin::modules::tmcm1636 {

using canopen::NmtState;

void Tmcm1636Canopen::format_factory_image(uint8_t* image, size_t size) { canopen::StorageImage::format(image, size); }

Tmcm1636Canopen::Tmcm1636Canopen(board::NonVolatileMemory& nvm, board::CanController& can, board::Tmcm1636Io& io,
                                 const canopen::NodeConfig& config)
    : io_(io),
      dictionary_(*this, object_table(), 1),
      node_(dictionary_, nvm, can, *this, kNode, config, storage_scratch_) {
  // Positions of the host's frame are 2058 units per revolution, as AP 56 of TMCL 1.13.
  axis_.set_position_scaler_applies(true);
}

// --- Frames --------------------------------------------------------------------------------------

int32_t Tmcm1636Canopen::drive_position(int32_t axis_counts) const { return directed(axis_.host_position(axis_counts)); }

int32_t Tmcm1636Canopen::axis_position(int32_t drive_units) const { return axis_.axis_position(directed(drive_units)); }

int32_t Tmcm1636Canopen::axis_reference(int32_t drive_units) const {
  const int32_t from = axis_.ramp_position();
  const auto delta =
      static_cast<int32_t>(static_cast<uint32_t>(drive_units) - static_cast<uint32_t>(drive_position(from)));
  return static_cast<int32_t>(static_cast<uint32_t>(from) + static_cast<uint32_t>(axis_position(delta)));
}

double Tmcm1636Canopen::drive_velocity(double axis_counts_per_s) const {
  const double v = axis_counts_per_s * frames_.drive_units_per_count;
  return axis_.config.motor_direction != 0 ? -v : v;
}

double Tmcm1636Canopen::axis_velocity(double drive_units_per_s) const {
  const double v = drive_units_per_s * frames_.counts_per_drive_unit;
  return axis_.config.motor_direction != 0 ? -v : v;
}

void Tmcm1636Canopen::refresh_frames() {
  const int32_t scaler = axis_.config.position_scaler;
  const int32_t steps = axis_.config.encoder_steps;
  if (scaler == frames_.position_scaler && steps == frames_.encoder_steps) return;
  frames_.position_scaler = scaler;
  frames_.encoder_steps = steps;
  frames_.drive_units_per_count = steps > 0 ? static_cast<double>(scaler) / steps : 0.0;
  frames_.counts_per_drive_unit = scaler > 0 ? static_cast<double>(steps) / scaler : 0.0;
}

// --- The application -----------------------------------------------------------------------------

void Tmcm1636Canopen::reset_application() {
  // Every object of 2000h..9FFFh as power-on builds it (CiA-301 reset application): the settings
  // value-initialised, then what 1010 stored (or each object's default) on top, then the live
  // state. The axis settings no object reaches keep the TMCL firmware's defaults.
  axis_.reset_state();  // parameter writes until finish_restore() are the restore
  axis_.config = AxisConfig{};
  drive_.objects = cia402::ProfileObjects{};
  drive_.manufacturer = Tmcm1636DriveObjects{};
  objects_ = Tmcm1636CanopenObjects{};
  node_.node_settings() = canopen::NodeSettings{};
  canopen::StorageSelection application;
  application.application = true;
  application.axis_mask = 1;
  application.node_settings = true;
  node_.load_stored(application);
  axis_.finish_restore();
  // The switches' electrical levels, high = active, as the family's 2005 reads them (it inverts
  // them, bit 2/3/5); the TMCL firmware's AP 210 has no object here. And the axis stops for no
  // switch itself (AP 209): the drive does, as 2005 says.
  axis_.config.reference_switch_polarity = 7;
  axis_.config.reference_switch_enable = 0;
  drive_.manufacturer.set_position_scaler(axis_.config.position_scaler);
  refresh_frames();
  // The power stage is off until the drive is switched on.
  axis_.set_driver_enabled(false);
  driver_enabled_ = false;
  drive_.reset(0);
  drive_ticks_ = 0;
  reported_protections_ = 0;
  axis_.set_actual_position(0);
  apply_outputs();
}

void Tmcm1636Canopen::on_bus_off() {
  // The master has lost the drive: a running one takes its fault reaction, as with NMT stopped.
  if (drive_.pds().power_enabled()) drive_.external_fault();
}

uint8_t Tmcm1636Canopen::application_error_register() const {
  uint8_t bits = 0;
  const cia402::PdsState state = drive_.state();
  if (state == cia402::PdsState::kFault || state == cia402::PdsState::kFaultReactionActive) {
    bits |= canopen::kErrorRegisterGeneric | canopen::kErrorRegisterDeviceProfile;
  }
  const uint32_t flags = axis_.state.status_flags;
  if ((flags & (status_flag::kUndervoltage | status_flag::kOvervoltage)) != 0) {
    bits |= canopen::kErrorRegisterGeneric | canopen::kErrorRegisterVoltage;
  }
  if ((flags & status_flag::kOvertemperature) != 0) {
    bits |= canopen::kErrorRegisterGeneric | canopen::kErrorRegisterTemperature;
  }
  return bits;
}

uint32_t Tmcm1636Canopen::status_flags() const {
  const uint32_t axis = axis_.state.status_flags;
  uint32_t flags = 0;
  if ((axis & status_flag::kUndervoltage) != 0) flags |= kFlagUndervoltage;
  if ((axis & status_flag::kOvervoltage) != 0) flags |= kFlagOvervoltage;
  if ((axis & status_flag::kOvertemperature) != 0) flags |= kFlagOvertemperature;
  if ((axis & status_flag::kHallError) != 0) flags |= kFlagHallError;
  if (axis_.state.actual_velocity_rpm == 0) flags |= kFlagMotorHalted;
  if (!driver_enabled_) {
    flags |= kFlagStopMode;
  } else {
    switch (axis_.state.mode) {
      case MotionMode::kVelocity: flags |= kFlagVelocityMode; break;
      case MotionMode::kPosition: flags |= kFlagPositionMode; break;
      case MotionMode::kTorque: flags |= kFlagTorqueMode; break;
    }
  }
  if (axis_.position_reached()) flags |= kFlagPositionEnd;
  // Commutation set up: on, and for an ABN encoder its offset found.
  const CommutationMode commutation = axis_.config.commutation_mode;
  if (commutation != CommutationMode::kDisabled &&
      (commutation != CommutationMode::kAbnEncoder || axis_.encoder_initialised() || !axis_.has_power_stage())) {
    flags |= kFlagInitialized;
  }
  return flags;
}

uint32_t Tmcm1636Canopen::device_digital_inputs() const {
  uint32_t bits = 0;
  for (uint8_t port = 0; port < board::Tmcm1636Io::kDigitalInputCount; ++port) {
    if (io_.digital_input(port)) bits |= 1u << port;
  }
  return bits;
}

uint32_t Tmcm1636Canopen::digital_inputs() const {
  const cia402::AxisInputs inputs = axis_inputs();
  uint32_t bits = (inputs.left_limit ? 1u : 0u) | (inputs.right_limit ? 2u : 0u) | (inputs.home_switch ? 4u : 0u);
  return bits | device_digital_inputs() << 16;
}

void Tmcm1636Canopen::write_outputs(uint32_t value) {
  objects_.outputs = value;
  objects_.output_levels =
      (objects_.output_levels & ~objects_.output_mask) | (value & objects_.output_mask & kCanopenOutputBits);
  apply_outputs();
}

void Tmcm1636Canopen::apply_outputs() {
  for (uint8_t port = 0; port < board::Tmcm1636Io::kDigitalOutputCount; ++port) {
    io_.set_digital_output(port, ((objects_.output_levels >> port) & 1u) != 0);
  }
}

// --- The tick ------------------------------------------------------------------------------------

void Tmcm1636Canopen::tick() {
  node_.tick(kControlTickUs);
  if (++drive_ticks_ == kDriveTicks) {
    drive_ticks_ = 0;
    run_drive(kDrivePeriodUs);
  }
  axis_.tick(io_, static_cast<double>(kControlTickUs) * 1e-6);
}

cia402::AxisInputs Tmcm1636Canopen::axis_inputs() const {
  cia402::AxisInputs inputs;
  inputs.encoder_position_usteps = drive_position(axis_.actual_position());
  inputs.actual_velocity_pps = drive_.units().velocity_pps(directed(axis_.state.actual_velocity_rpm));
  // The switches' levels (the axis reads them high-active: reset_application), then 2005, in the
  // host's direction: with 2057 set the motor's right switch is the host's negative limit.
  const bool inverted = axis_.config.motor_direction != 0;
  const bool motor_left = axis_.state.left_switch_active != 0;
  const bool motor_right = axis_.state.right_switch_active != 0;
  const cia402::Switches active =
      cia402::active_switches(objects_.switch_parameters, {inverted ? motor_right : motor_left,
                                                           inverted ? motor_left : motor_right,
                                                           axis_.state.home_switch_active != 0});
  inputs.left_limit = active.left;
  inputs.right_limit = active.right;
  inputs.home_switch = active.home;
  inputs.index_available = false;  // the index methods (1..14, 33, 34) are not this firmware's
  const uint32_t flags = axis_.state.status_flags;
  inputs.power_stage_fault =
      (flags & (status_flag::kUndervoltage | status_flag::kOvervoltage | status_flag::kOvertemperature)) != 0;
  inputs.ready = true;
  return inputs;
}

void Tmcm1636Canopen::run_drive(uint32_t dt_us) {
  refresh_frames();
  // NMT stopped takes the drive function away from a running axis: FAULT.
  if (configured() && nmt_state() == NmtState::kStopped && drive_.state() == cia402::PdsState::kOperationEnabled) {
    drive_.external_fault();
  }
  // A position the drive assigned (a homing attained) is the axis' counter before the drive reads
  // it: homing 0 and 35 attain when the controlword is written, between two runs, and the run
  // after read the counter as it was, a following error against the home offset (fuzz/README.md
  // "Findings"); the others attain within the step.
  int32_t position = 0;
  if (drive_.take_position_assignment(position)) axis_.set_actual_position(axis_position(position));
  drive_.step(axis_inputs(), dt_us);
  if (drive_.take_position_assignment(position)) axis_.set_actual_position(axis_position(position));
  carry_out(drive_.demand());
  report_drive_emergencies();
}

void Tmcm1636Canopen::carry_out(const cia402::AxisDemand& demand) {
  if (demand.power_enabled != driver_enabled_) {
    driver_enabled_ = demand.power_enabled;
    axis_.set_driver_enabled(driver_enabled_);
  }
  axis_.state.release_brake = demand.brake_released_request ? 1 : 0;
  // With the power stage off there is nothing to follow: a servo's reference follows its coasting
  // motor by itself and the ideal motor stands. A demand handed over then moved the ideal motor
  // without power: a drive enabled and quick-stopped between two runs ends in SWITCH ON DISABLED
  // within one run, holding the demand it had (fuzz/README.md "Findings").
  if (!demand.power_enabled) return;
  switch (demand.control) {
    case cia402::DriveControl::kPosition:
      axis_.follow_position(axis_reference(demand.position_usteps), axis_velocity(demand.velocity_exact_pps));
      break;
    case cia402::DriveControl::kVelocity: axis_.follow_velocity(axis_velocity(demand.velocity_exact_pps)); break;
    case cia402::DriveControl::kTorque: {
      const int32_t torque_ma = directed(demand.torque);
      if (axis_.state.mode != MotionMode::kTorque || axis_.state.target_torque_ma != torque_ma) {
        axis_.set_target_torque(torque_ma);
      }
      break;
    }
  }
}

void Tmcm1636Canopen::report_drive_emergencies() {
  cia402::AxisEmergency emcy;
  while (drive_.take_emergency(emcy)) {
    const uint8_t data[5] = {emcy.sub, 0, 0, 0, 0};
    node_.emergency().report(emcy.code, error_register(), data);
  }
  // A protection that trips: its EMCY once (the drive goes to FAULT, power_stage_fault); all gone:
  // 0000.
  struct Protection {
    uint32_t flag;
    uint16_t code;
    uint8_t byte3;
  };
  static constexpr Protection kProtections[] = {{status_flag::kUndervoltage, kCanopenEmcyUndervoltage, 0},
                                                {status_flag::kOvervoltage, kCanopenEmcyOvervoltage, 0},
                                                {status_flag::kOvertemperature, kCanopenEmcyOvertemperature, 2}};
  uint32_t active = 0;
  for (const Protection& p : kProtections) active |= axis_.state.status_flags & p.flag;
  for (const Protection& p : kProtections) {
    if ((active & p.flag) == 0 || (reported_protections_ & p.flag) != 0) continue;
    const uint8_t data[5] = {p.byte3, 0, 0, 0, 0};
    node_.emergency().report(p.code, error_register(), data);
  }
  if (active == 0 && reported_protections_ != 0) {
    const uint8_t data[5] = {};
    node_.emergency().report(canopen::kEmcyErrorReset, error_register(), data);
  }
  reported_protections_ = active;
}

}  // namespace motwin::modules::tmcm1636

template class motwin::canopen::TableDictionary<motwin::modules::tmcm1636::Tmcm1636Canopen>;
