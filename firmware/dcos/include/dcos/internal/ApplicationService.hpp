// Drivers that take part in starting an application.
//
// Some declarations of an application are served by a driver rather than
// by a kernel agent: the Modbus register map and slave (drivers/modbus) are
// the first. The kernel cannot include its drivers, so each such driver
// registers one ApplicationService with DCOS_APPLICATION_SERVICE in its own
// source file; the linker gathers them into the section
// dcos_application_services, and the application loader calls them:
//
//   - start(), after every object of the application exists and before any
//     of its tasks runs (dispatching is held), in the root task: the
//     service takes what it serves (a publisher handed to its task, a
//     device installed), or returns the error that names what it could not
//     take, and the loader then deletes the whole application;
//   - stop(), when the application is stopped, or when a later service
//     refused, so that nothing keeps serving objects that are gone.
//
// An image without the driver has no service and the declarations stay
// unserved, as the driver's own commands then say.
#pragma once

#include <dcos/ConfigurationRules.hpp>

namespace dcos::internal {

struct ApplicationService {
    /// The driver, for diagnostics.
    const char* name;
    /// Takes up the application's declarations this driver serves; rule None when it did (or had nothing to do).
    app::ConfigurationError (*start)(const app::Application& application);
    /// Stops serving them; a service that did not start does nothing.
    void (*stop)(const app::Application& application);
};

/// The services linked into this image, in link order.
const ApplicationService* applicationServicesBegin();
const ApplicationService* applicationServicesEnd();

} // namespace dcos::internal

#define DCOS_APPLICATION_SERVICE(identifier, name, start, stop)                                                 \
    [[gnu::used, gnu::section("dcos_application_services"), gnu::aligned(alignof(::dcos::internal::ApplicationService))]] \
    constinit const ::dcos::internal::ApplicationService identifier{name, start, stop}
