#include <boot/Panic.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/CpuException.hpp>
#include <arch_x86/FaultTasks.hpp>
#include <arch_x86/Paging.hpp>

#include <stdarg.h>

namespace {

// Set on entry so that a fault inside the panic path itself does not recurse
// forever but stops at once with a short note.
volatile bool panicking = false;

void printControlRegisters(runtime::CharacterSink& out)
{
    runtime::format(out, "CR0=%08lx CR2=%08lx CR3=%08lx\r\n", static_cast<unsigned long>(arch_x86::readCr0()),
                    static_cast<unsigned long>(arch_x86::readCr2()),
                    static_cast<unsigned long>(arch_x86::readCr3()));
}

// The firmware's code, from the linker script: a return address lies in it.
extern "C" const uint8_t __text_start[];
extern "C" const uint8_t __text_end[];

// The length of an indirect CALL (FF /2, Intel SDM Vol. 2A, "CALL") whose
// ModR/M byte is @p modrm and whose next byte, a SIB byte where the ModR/M
// calls for one, is @p sib: 2 to 7 bytes.
constexpr unsigned indirectCallLength(uint8_t modrm, uint8_t sib)
{
    const unsigned mod = modrm >> 6;
    const unsigned rm = modrm & 7u;
    const bool hasSib = mod != 3 && rm == 4;
    switch (mod) {
    case 0:
        if (hasSib) {
            return (sib & 7u) == 5 ? 7 : 3; // A SIB with no base register takes a 32-bit displacement.
        }
        return rm == 5 ? 6 : 2; // rm 5 without a register is a 32-bit absolute address.
    case 1:
        return hasSib ? 4 : 3;
    case 2:
        return hasSib ? 7 : 6;
    default:
        return 2;
    }
}
static_assert(indirectCallLength(0xD0, 0) == 2 && indirectCallLength(0x15, 0) == 6 &&
              indirectCallLength(0x14, 0x85) == 7 && indirectCallLength(0x54, 0x24) == 4);

// Whether @p address, in the firmware's code, follows a CALL instruction,
// direct (E8 and a 32-bit offset) or indirect, so that it can be a return
// address rather than a code address some other value happens to equal.
bool followsCall(uintptr_t address)
{
    if (address < reinterpret_cast<uintptr_t>(__text_start) + 7 || address >= reinterpret_cast<uintptr_t>(__text_end)) {
        return false;
    }
    const uint8_t* const end = reinterpret_cast<const uint8_t*>(address);
    if (end[-5] == 0xE8) {
        return true;
    }
    for (unsigned length = 2; length <= 7; ++length) {
        const uint8_t* const call = end - length;
        if (call[0] == 0xFF && ((call[1] >> 3) & 7u) == 2 && indirectCallLength(call[1], call[2]) == length) {
            return true;
        }
    }
    return false;
}

// Lists the return addresses on the stack above @p stackPointer, innermost
// first, up to a bounded number. The firmware is compiled without frame
// pointers (mk/firmware.mk: EBP is one more register on the real-time
// paths), so there is no chain of frames to follow; the stack is scanned
// instead, as the Linux kernel does without frame pointers, for words that
// lie in the code and follow a CALL. A stale return address left in a
// frame's unused slots can appear too: the list is for reading beside the
// code, which the lab does (tests_renode/dcoslab/symbolize.py). The scan
// reads at most 4 KiB and stops at the first page that is not present, so
// it never faults at a stack's guard page or beyond its top.
void printBackTrace(runtime::CharacterSink& out, uint32_t stackPointer)
{
    constexpr unsigned kMostAddresses = 12;
    constexpr unsigned kMostWords = 1024;
    runtime::format(out, "back trace:");
    unsigned found = 0;
    uintptr_t at = stackPointer & ~uintptr_t{3};
    uintptr_t checkedPage = 1; // No page starts here: the first word's page is checked.
    for (unsigned word = 0; word < kMostWords && found < kMostAddresses && at != 0; ++word, at += 4) {
        const uintptr_t page = arch_x86::Paging::pageBase(at);
        if (page != checkedPage) {
            if (arch_x86::Paging::enabled() && !arch_x86::Paging::isPresent(at)) {
                break;
            }
            checkedPage = page;
        }
        const uint32_t value = *reinterpret_cast<const volatile uint32_t*>(at);
        if (followsCall(value)) {
            runtime::format(out, " %08lx", static_cast<unsigned long>(value));
            ++found;
        }
    }
    runtime::format(out, "\r\n");
}

bool enterPanic()
{
    arch_x86::disableInterrupts();
    if (panicking) {
        runtime::format(boot::panicConsole(), "\r\n*** DCOS PANIC while panicking\r\n");
        return false;
    }
    panicking = true;
    return true;
}

} // namespace

extern "C" [[gnu::weak, noreturn]] void dcosPanicHalt()
{
    for (;;) {
        arch_x86::disableInterrupts();
        arch_x86::haltUntilInterrupt();
    }
}

extern "C" [[noreturn]] void dcosPanic(const char* format, ...)
{
    if (enterPanic()) {
        runtime::CharacterSink& out = boot::panicConsole();
        runtime::format(out, "\r\n*** DCOS PANIC: ");
        va_list arguments;
        va_start(arguments, format);
        runtime::formatTo(out, format, arguments);
        va_end(arguments);
        const uint32_t caller = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(__builtin_return_address(0)));
        uint32_t esp;
        uint32_t ebp;
        asm volatile("movl %%esp, %0; movl %%ebp, %1" : "=r"(esp), "=r"(ebp));
        runtime::format(out, "\r\ncalled from EIP=%08lx ESP=%08lx EBP=%08lx EFLAGS=%08lx\r\n",
                        static_cast<unsigned long>(caller), static_cast<unsigned long>(esp),
                        static_cast<unsigned long>(ebp), static_cast<unsigned long>(arch_x86::readEflags()));
        printControlRegisters(out);
        printBackTrace(out, esp);
        runtime::format(out, "*** system halted\r\n");
    }
    dcosPanicHalt();
}

extern "C" [[noreturn]] void dcosPanicWithFrame(const arch_x86::InterruptFrame* frame, const char* reason)
{
    if (enterPanic()) {
        runtime::CharacterSink& out = boot::panicConsole();
        const unsigned vector = frame->vector;
        const bool isException = vector < arch_x86::exceptionVectorCount;
        runtime::format(out, "\r\n*** DCOS PANIC: %s\r\n", reason);
        runtime::format(out, "vector %u (%s %s) error code %08lx\r\n", vector,
                        isException ? arch_x86::exceptionMnemonic(vector) : "IRQ",
                        isException ? arch_x86::exceptionName(vector) : "interrupt",
                        static_cast<unsigned long>(frame->errorCode));
        // A frame a fault task built was copied off the faulting stack, so
        // the stack pointer is the one the fault task recorded.
        const bool faultFrame = arch_x86::FaultTasks::isFaultFrame(frame);
        const uint32_t esp = faultFrame ? arch_x86::FaultTasks::lastFault().stackPointer : frame->interruptedEsp();
        runtime::format(out, "EIP=%08lx CS=%04lx EFLAGS=%08lx ESP=%08lx\r\n", static_cast<unsigned long>(frame->eip),
                        static_cast<unsigned long>(frame->cs), static_cast<unsigned long>(frame->eflags),
                        static_cast<unsigned long>(esp));
        runtime::format(out, "EAX=%08lx EBX=%08lx ECX=%08lx EDX=%08lx\r\n", static_cast<unsigned long>(frame->eax),
                        static_cast<unsigned long>(frame->ebx), static_cast<unsigned long>(frame->ecx),
                        static_cast<unsigned long>(frame->edx));
        runtime::format(out, "ESI=%08lx EDI=%08lx EBP=%08lx\r\n", static_cast<unsigned long>(frame->esi),
                        static_cast<unsigned long>(frame->edi), static_cast<unsigned long>(frame->ebp));
        runtime::format(out, "DS=%04lx ES=%04lx FS=%04lx GS=%04lx\r\n", static_cast<unsigned long>(frame->ds),
                        static_cast<unsigned long>(frame->es), static_cast<unsigned long>(frame->fs),
                        static_cast<unsigned long>(frame->gs));
        printControlRegisters(out);
        printBackTrace(out, esp);
        runtime::format(out, "*** system halted\r\n");
    }
    dcosPanicHalt();
}
