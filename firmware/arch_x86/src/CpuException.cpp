#include <arch_x86/CpuException.hpp>

namespace arch_x86 {

namespace {

struct ExceptionNames {
    const char* mnemonic;
    const char* name;
};

// Intel SDM Vol. 3, Table 6-1. Vector 15 and 19 to 31 are reserved on the
// i486 (19 and 20 arrived later with SIMD and virtualisation).
constexpr ExceptionNames names[] = {
    {"#DE", "divide error"},
    {"#DB", "debug"},
    {"NMI", "non-maskable interrupt"},
    {"#BP", "breakpoint"},
    {"#OF", "overflow"},
    {"#BR", "bound range exceeded"},
    {"#UD", "invalid opcode"},
    {"#NM", "device not available"},
    {"#DF", "double fault"},
    {"#MF9", "coprocessor segment overrun"},
    {"#TS", "invalid TSS"},
    {"#NP", "segment not present"},
    {"#SS", "stack-segment fault"},
    {"#GP", "general protection"},
    {"#PF", "page fault"},
    {"#15", "reserved"},
    {"#MF", "x87 floating-point error"},
    {"#AC", "alignment check"},
    {"#MC", "machine check"},
};

} // namespace

const char* exceptionMnemonic(unsigned vector)
{
    return vector < sizeof names / sizeof names[0] ? names[vector].mnemonic : "#??";
}

const char* exceptionName(unsigned vector)
{
    return vector < sizeof names / sizeof names[0] ? names[vector].name : "reserved";
}

} // namespace arch_x86
