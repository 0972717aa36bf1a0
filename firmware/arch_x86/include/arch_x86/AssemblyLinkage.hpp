// How C++ functions and the assembly stubs call each other.
//
// The firmware is compiled with -mregparm=3 (mk/firmware.mk): a call passes
// its first three word-sized arguments in EAX, EDX and ECX rather than on the
// stack, which saves the pushes and the loads on every call of a kernel
// service. The stubs in *.S files follow the stack convention instead, which
// keeps them readable and lets the CPU's own frames double as arguments (an
// interrupt stub passes its ESP). A function an assembly stub calls, or one
// written in assembly and called from C++, is therefore declared with
// DCOS_ASM_LINKAGE, which asks for all of its arguments on the stack. The
// Linux kernel's i386 "asmlinkage" is the same idea.
#pragma once

#if defined(__i386__)
#define DCOS_ASM_LINKAGE extern "C" [[gnu::regparm(0)]]
#else
// Host builds (unit tests with mocked hardware) have one calling convention.
#define DCOS_ASM_LINKAGE extern "C"
#endif

// The exception: a function on the interrupt path, whose every instruction
// counts in interrupt latency, takes its argument in EAX (regparm), which
// its stub loads with one move instead of a push and a load.
#if defined(__i386__)
#define DCOS_ASM_REGISTER_LINKAGE extern "C" [[gnu::regparm(3)]]
#else
#define DCOS_ASM_REGISTER_LINKAGE extern "C"
#endif
