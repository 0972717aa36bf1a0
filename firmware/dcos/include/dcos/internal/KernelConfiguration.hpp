// The kernel configuration an image is linked with (docs/guide/kernel-configurations.md).
//
// Every configuration shares the kernel's core: the system, scheduler, task
// and timer agents and what boot needs (kernel/Kernel.cpp). What differs is
// which other agents are linked and what the root task does, and each
// configuration brings that in one source file of its own:
//
//   full     kernel/ConsoleRoot.cpp: the memory, port, DSM and semaphore
//            agents, the application loader, the console shell and its
//            commands, the drivers (build/486/dcos486.elf, libdcos486.a).
//   minimal  kernel/MinimalRoot.cpp: the core only; the root task starts the
//            linked application's tasks (build/486/dcos486-minimal.elf,
//            libdcos486-minimal.a).
//
// An agent a configuration leaves out is not linked at all: a call to one
// of its primitives is an undefined reference when the image is linked,
// never a run-time error (see the guide).
#pragma once

#include <dcos/ApplicationDeclarations.hpp>

#include <stdint.h>

namespace dcos::internal {

/// The configuration's name, printed at boot: "full" or "minimal".
extern const char* const kKernelConfiguration;

/// The root task's entry, defined by the configuration. The kernel creates
/// the root task (kRootTaskName) when it starts scheduling; it starts the
/// linked application.
void rootTaskEntry(uintptr_t);

/// The application linked into the image (DCOS_APPLICATION), or null.
const app::Application* linkedApplication();

} // namespace dcos::internal
