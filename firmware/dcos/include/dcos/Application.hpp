// A controller application's configuration: its tasks and objects, declared
// in one place (seed 8.2).
//
// A control engineer keeps an application in a directory of their own and
// builds it against DCOS (docs/guide/first-application.md). One source file
// of the application declares everything the node must create for it before
// any of its tasks runs:
//
//     dcos::ObjectId samplesPort;   // the loader stores the port's id here
//
//     constexpr dcos::app::TaskDeclaration tasks[] = {
//         {.name = "sampler", .entry = sampler, .priority = 8, .stackSize = 4096},
//         {.name = "logger", .entry = logger, .priority = 20},
//     };
//     constexpr dcos::app::MessagePortDeclaration ports[] = {
//         {.name = "samples", .receiver = "logger", .id = &samplesPort},
//     };
//     DCOS_APPLICATION(loggerApplication, {.name = "logger", .tasks = tasks, .messagePorts = ports});
//
// The declarations are checked when the file is compiled: a priority out of
// range, a stack too small, a duplicate name or more objects of a type than
// the node's tables hold is a compile-time error that names the object
// (internal/ConfigurationCheck.hpp). What only the running node knows (free
// table slots, free stack memory, names its drivers already use) is checked
// again at boot by the application loader, which then either creates every
// object or none, and prints an error that names the object.
//
// At boot the loader, in the root task, creates the semaphores, ports,
// publishers, pools and heaps, then the tasks, hands each object to the task
// declared as its owner, stores every id where the declaration's id field
// points, and only then lets the tasks run, most urgent first. Objects with
// no owner belong to the system (null owner) and live as long as the node.
#pragma once

#include <dcos/ApplicationDeclarations.hpp>
#include <dcos/internal/ConfigurationCheck.hpp>

/// Declares the image's application. Exactly one source file of an
/// application uses it; a second one in the same image is a link error
/// (the symbol dcosApplication is defined twice). The configuration is
/// checked at compile time (see the top of this file).
#define DCOS_APPLICATION(identifier, ...)                                                               \
    constexpr ::dcos::app::Application identifier = __VA_ARGS__;                                      \
    static_assert(::dcos::internal::ConfigurationCheck<identifier>::passed,     \
                  "DCOS_APPLICATION: the configuration breaks the rule named above");                         \
    extern "C" constinit const ::dcos::app::Application* const dcosApplication = &identifier
