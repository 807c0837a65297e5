# Toolchain for the firmware images (scripts/build-firmware.sh, docs/firmware.md): a Cortex-M4F
# with its single-precision FPU (hard-float ABI), Debian's gcc-arm-none-eabi and newlib nano.
# -Os with a section per function and object and --gc-sections: an image keeps only what its
# module calls. No exceptions, no RTTI, no thread-safe statics (one thread, no RTOS), and the
# C++ library is not linked (-nodefaultlibs, then only newlib nano's C and math libraries and
# libgcc): the core and the board use its headers only, so libstdc++-arm-none-eabi-dev is enough.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
# Compiler checks link a program: a static library needs no start-up code or linker script.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(MOTWIN_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(CMAKE_CXX_FLAGS_INIT
    "${MOTWIN_CPU_FLAGS} -fno-exceptions -fno-rtti -fno-threadsafe-statics -ffunction-sections -fdata-sections")
set(CMAKE_C_FLAGS_INIT "${MOTWIN_CPU_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_MINSIZEREL_INIT "-Os -DNDEBUG")
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "${MOTWIN_CPU_FLAGS} --specs=nano.specs --specs=nosys.specs -nostartfiles -nodefaultlibs -Wl,--gc-sections")
set(CMAKE_CXX_STANDARD_LIBRARIES_INIT "-Wl,--start-group -lc -lm -lgcc -lnosys -Wl,--end-group")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
