// The one instantiation of the generic CiA-402 drive with the TMCM-1636 CANopen firmware's part:
// the drive's code is compiled here, with the module's hooks inlined into it.
#include "core/modules/tmcm1636/tmcm1636_canopen_drive.h"

#include "core/cia402/axis_drive_impl.h"

template class motwin::cia402::AxisDrive<motwin::modules::tmcm1636::Tmcm1636DriveObjects>;
