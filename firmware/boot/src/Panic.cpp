#include <boot/Panic.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/CpuException.hpp>
#include <arch_x86/FaultTasks.hpp>

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

// Walks the saved frame pointers (the firmware keeps them) up to a bounded
// depth; the boot stub pushes a zero frame pointer that ends the walk.
void printBackTrace(runtime::CharacterSink& out, uint32_t ebp)
{
    runtime::format(out, "back trace:");
    for (unsigned depth = 0; depth < 12 && ebp != 0 && (ebp & 3) == 0 && ebp >= 0x100000; ++depth) {
        const uint32_t* frame = reinterpret_cast<const uint32_t*>(ebp);
        runtime::format(out, " %08lx", static_cast<unsigned long>(frame[1]));
        if (frame[0] <= ebp) {
            break; // Frames must move up the stack; anything else is corrupt.
        }
        ebp = frame[0];
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
        printBackTrace(out, ebp);
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
        printBackTrace(out, frame->ebp);
        runtime::format(out, "*** system halted\r\n");
    }
    dcosPanicHalt();
}
