// Messages for broken configuration rules; portable, so the host tests check every wording.
#include <dcos/internal/ConfigurationReport.hpp>

namespace dcos::internal {

namespace {

using app::ConfigurationRule;

// Whether value and limit mean something for the rule, so the message shows them.
bool showsValueAndLimit(ConfigurationRule rule)
{
    switch (rule) {
    case ConfigurationRule::NameTooLong:
    case ConfigurationRule::PriorityOutOfRange:
    case ConfigurationRule::StackTooSmall:
    case ConfigurationRule::StacksExceedArena:
    case ConfigurationRule::TooManyObjects:
    case ConfigurationRule::InitialCountTooLarge:
    case ConfigurationRule::TickRateOutOfRange:
    case ConfigurationRule::AreaTooSmall:
    case ConfigurationRule::BufferTooSmall:
    case ConfigurationRule::MapAddressPastEnd:
    case ConfigurationRule::MapTooLarge:
    case ConfigurationRule::MapOverlap:
    case ConfigurationRule::SlaveAddressOutOfRange:
    case ConfigurationRule::BaudOutOfRange:
    case ConfigurationRule::PollPeriodOutOfRange:
    case ConfigurationRule::TimeoutOutOfRange:
    case ConfigurationRule::RetriesOutOfRange:
        return true;
    default:
        return false;
    }
}

} // namespace

void formatConfigurationError(runtime::CharacterSink& sink, const char* application,
                              const app::ConfigurationError& error)
{
    runtime::format(sink, "application '%s' not started: ", application != nullptr ? application : "");
    const char* kind = app::objectKindName(error.kind);
    if (error.rule == ConfigurationRule::NameMissing && error.kind != app::ObjectKind::Application) {
        runtime::format(sink, "%s number %lu in its list %s", kind, static_cast<unsigned long>(error.value + 1),
                        app::ruleText(error.rule));
        return;
    }
    if (error.kind == app::ObjectKind::Application) {
        runtime::format(sink, "the application %s", app::ruleText(error.rule));
    } else {
        runtime::format(sink, "%s '%s' %s", kind, error.object != nullptr ? error.object : "",
                        app::ruleText(error.rule));
    }
    if (error.rule == ConfigurationRule::CreateFailed) {
        runtime::format(sink, " (%s)", statusName(static_cast<Status>(error.value)));
    } else if (showsValueAndLimit(error.rule)) {
        runtime::format(sink, " (%lu, limit %lu)", static_cast<unsigned long>(error.value),
                        static_cast<unsigned long>(error.limit));
    }
}

} // namespace dcos::internal
