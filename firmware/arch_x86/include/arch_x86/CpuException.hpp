// Names of the processor exception vectors (Intel SDM Vol. 3, Table 6-1).
#pragma once

#include <stdint.h>

namespace arch_x86 {

enum class CpuException : uint8_t {
    DivideError = 0,
    Debug = 1,
    NonMaskableInterrupt = 2,
    Breakpoint = 3,
    Overflow = 4,
    BoundRangeExceeded = 5,
    InvalidOpcode = 6,
    DeviceNotAvailable = 7,
    DoubleFault = 8,
    CoprocessorSegmentOverrun = 9,
    InvalidTss = 10,
    SegmentNotPresent = 11,
    StackSegmentFault = 12,
    GeneralProtection = 13,
    PageFault = 14,
    FloatingPointError = 16,
    AlignmentCheck = 17,
    MachineCheck = 18,
};

/// Number of vectors Intel reserves for exceptions.
constexpr unsigned exceptionVectorCount = 32;

/// The mnemonic, e.g. "#DE", for an exception vector, or "#??" if reserved.
const char* exceptionMnemonic(unsigned vector);

/// The descriptive name, e.g. "divide error", for an exception vector.
const char* exceptionName(unsigned vector);

} // namespace arch_x86
