// The assembly entry points that move the processor from one task's stack
// to another's (InterruptStubs.S). The scheduler decides; these only switch.
#pragma once

#include <arch_x86/AssemblyLinkage.hpp>
#include <arch_x86/InterruptFrame.hpp>

#include <stdint.h>

/// Starts the first task by "returning" into its initial frame; never returns.
DCOS_ASM_LINKAGE [[noreturn]] void resumeInterruptFrame(arch_x86::InterruptFrame* frame);

/// Saves the caller's callee-saved registers and return address on its
/// stack, stores that stack pointer at *save, and resumes the next task: at
/// resumeStack when it left through here too, else from its interrupt frame.
/// Returns when another switch resumes the caller. The caller disables
/// interrupts first and restores its own flags afterwards.
extern "C" [[gnu::regparm(3)]] void directSwitch(uint32_t** save, uint32_t* resumeStack,
                                                 arch_x86::InterruptFrame* frame);

/// Where a task parked by directSwitch resumes when an interrupt frame is
/// built for it (the frame's EIP): it pops what directSwitch pushed and returns.
extern "C" void directResume();
