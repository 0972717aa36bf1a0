// The assembly entry points that move the processor from one task's stack
// to another's (InterruptStubs.S; the switch from task context is the
// kernel's, dcos/src/scheduler/TaskContextSwitch.S, as it knows a Task).
// The scheduler decides; these only switch.
#pragma once

#include <arch_x86/AssemblyLinkage.hpp>
#include <arch_x86/InterruptFrame.hpp>

#include <stdint.h>

/// Starts the first task by "returning" into its initial frame; never returns.
DCOS_ASM_LINKAGE [[noreturn]] void resumeInterruptFrame(arch_x86::InterruptFrame* frame);

/// Where a task parked by the switch from task context (the kernel's
/// dcosSwitchFromTask) resumes when an interrupt frame is built for it (the
/// frame's EIP): it pops the four registers that switch pushed and returns.
extern "C" void directResume();
