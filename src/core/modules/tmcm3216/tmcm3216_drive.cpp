// The one instantiation of the generic CiA-402 drive with the TMCM-3216's part: the drive's code
// is compiled here, with the module's hooks inlined into it.
#include "core/modules/tmcm3216/tmcm3216_drive.h"

#include "core/cia402/axis_drive_impl.h"

template class motwin::cia402::AxisDrive<motwin::modules::tmcm3216::Tmcm3216DriveObjects>;
