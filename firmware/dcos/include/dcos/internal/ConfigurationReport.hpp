// The one-line message that says why an application was not started.
#pragma once

#include <dcos/ConfigurationRules.hpp>
#include <runtime/Format.hpp>

namespace dcos::internal {

/// Prints, without a line end:
///   application 'demo' not started: task 'consumer' has a priority out of range (0 highest to 31 lowest) (40, limit 31)
/// @p application may be null (an application with no name). For
/// CreateFailed, error.value holds the agent's Status, which is named.
void formatConfigurationError(runtime::CharacterSink& sink, const char* application,
                              const app::ConfigurationError& error);

} // namespace dcos::internal
