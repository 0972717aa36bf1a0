// The last-resort path: report what went wrong and stop the node.
//
// A panic writes through the board's polled console output, which works with
// interrupts off and whatever state the interrupt-driven driver was left in,
// then halts the CPU. Boards and test images can replace the final halt (for
// example to signal the emulator), but nothing returns from a panic.
#pragma once

#include <arch_x86/InterruptFrame.hpp>
#include <runtime/Format.hpp>

extern "C" {

/// Prints "DCOS PANIC: <message>", the registers of the caller, the return
/// addresses found on its stack (the back trace), and halts.
[[noreturn]] void dcosPanic(const char* format, ...) __attribute__((format(printf, 1, 2)));

/// Prints a panic report for a trapped CPU state: the vector, its name, the
/// error code, every saved register and the control registers, then halts.
[[noreturn]] void dcosPanicWithFrame(const arch_x86::InterruptFrame* frame, const char* reason);

/// Called last, with interrupts disabled. The default halts forever; the
/// test image overrides it to report the panic to the emulator.
[[noreturn]] void dcosPanicHalt();
}

namespace boot {

/// The polled console the panic path writes to. Each board supplies it.
runtime::CharacterSink& panicConsole();

} // namespace boot
