// Turns a broken configuration rule into a compile-time error that names the object.
//
// DCOS_APPLICATION instantiates ConfigurationCheck<application>, which runs
// findConfigurationError (dcos/ConfigurationRules.hpp) in the compiler and
// instantiates ConfigurationRejected with the result. The compiler prints the
// instantiation with its arguments, which carry the object's kind and name,
// the rule, the value and the limit, and then the static_assert of the rule:
//
//   In instantiation of 'struct dcos::internal::ConfigurationRejected<
//       dcos::app::ObjectKind::Task, dcos::internal::ObjectName{"blinker"},
//       dcos::app::ConfigurationRule::PriorityOutOfRange, 40, 31>':
//   error: static assertion failed: a task's priority must be 0 (highest) to 31 (lowest)
//
// C++20 offers no other way to put a computed string in a diagnostic: a
// static_assert message must be a literal, so the name travels as a
// template argument of class type.
#pragma once

#include <dcos/ConfigurationRules.hpp>

#include <stddef.h>

namespace dcos::internal {

/// An object's name as a template argument, so that diagnostics print it.
struct ObjectName {
    char text[app::kMaximumApplicationName + 1] = {};

    consteval ObjectName(const char* name)
    {
        const char* source = name == nullptr ? "(unnamed)" : name;
        for (size_t i = 0; i < app::kMaximumApplicationName && source[i] != '\0'; ++i) {
            text[i] = source[i];
        }
    }
};

template <app::ObjectKind kind, ObjectName object, app::ConfigurationRule rule, size_t value, size_t limit>
struct ConfigurationRejected {
    using Rule = app::ConfigurationRule;
    static_assert(rule != Rule::NameMissing, "every object needs a name (value: its index in its list)");
    static_assert(rule != Rule::NameTooLong, "the name is too long (value: its length, limit: the longest allowed)");
    static_assert(rule != Rule::DuplicateName, "two objects of this kind have this name; names are unique per kind");
    static_assert(rule != Rule::ReservedName, "this is the name of a kernel task (idle, console, shell)");
    static_assert(rule != Rule::EntryMissing, "the task has no entry function");
    static_assert(rule != Rule::PriorityOutOfRange, "a task's priority must be 0 (highest) to 31 (lowest)");
    static_assert(rule != Rule::StackTooSmall, "the task's stack is smaller than dcos::kMinimumStackSize (limit)");
    static_assert(rule != Rule::StacksExceedArena,
                  "the stacks up to this task need more than the stack arena (DCOS_CONFIG_STACK_ARENA_KIB)");
    static_assert(rule != Rule::TooManyObjects,
                  "too many objects of this kind: value counts them with the kernel's own, limit is the table "
                  "(DCOS_CONFIG_*_CAPACITY); this is the first that does not fit");
    static_assert(rule != Rule::OwnerNotDeclared, "its owner, receiver or writer is not a declared task");
    static_assert(rule != Rule::ReceiverMissing, "a message port needs a receiver task");
    static_assert(rule != Rule::InitialCountTooLarge, "the semaphore's initial count is above its maximum (limit)");
    static_assert(rule != Rule::InheritanceNeedsBinary, "only binary semaphores have priority inheritance");
    static_assert(rule != Rule::TickRateOutOfRange, "the tick rate must be 19 to 10000 Hz, or 0 for the board's default");
    static_assert(rule != Rule::AreaMissing, "the pool or heap has no memory area");
    static_assert(rule != Rule::AreaTooSmall, "the area holds not even one buffer or segment (limit: the least)");
    static_assert(rule != Rule::BufferTooSmall, "buffers must be at least BufferPoolAgent::kMinimumBufferSize");
    static_assert(rule != Rule::MapRangeEmpty, "a Modbus map entry needs a count of at least 1");
    static_assert(rule != Rule::MapAddressPastEnd,
                  "the Modbus map entry runs past address 65535 (value: its last address, limit: 65535)");
    static_assert(rule != Rule::MapSourceWrongTable,
                  "analog inputs map to registers and digital outputs to coils or discrete inputs");
    static_assert(rule != Rule::MapObjectNotDeclared, "the Modbus map entry's object is not a declared publisher");
    static_assert(rule != Rule::MapTooLarge,
                  "the Modbus map entry does not fit its source (value: the page bytes or I/O points it needs, "
                  "limit: what there is)");
    static_assert(rule != Rule::MapWritesReadOnly,
                  "a coil or holding register entry is bound to something read-only (an analog input, or a "
                  "publisher with a writer task)");
    static_assert(rule != Rule::MapOverlap,
                  "the Modbus map entry overlaps an earlier entry of its table (value: the first shared address, "
                  "limit: the last)");
    static_assert(rule != Rule::SlaveAddressOutOfRange,
                  "a Modbus slave address must be 1 to 247 (the declared slave's may be 0 for none; value: the "
                  "address, limit: 247)");
    static_assert(rule != Rule::BaudOutOfRange,
                  "the Modbus line's baud rate must be 300 to 115200 (value: the rate, limit: the highest)");
    static_assert(rule != Rule::SlaveWithoutMap, "a Modbus slave is declared but the register map is empty");
    static_assert(rule != Rule::PollPeriodOutOfRange,
                  "a Modbus poll entry's period must be 1 to 3600000 ms (value: the period, limit: the longest)");
    static_assert(rule != Rule::PollWritesReadOnlyTable,
                  "a Modbus poll entry writes only coils or holding registers");
    static_assert(rule != Rule::PollPublisherHasWriter,
                  "a Modbus poll read publishes on a publisher with no writer task that the slave's map does not "
                  "write either (one writer per publisher)");
    static_assert(rule != Rule::TimeoutOutOfRange,
                  "the Modbus master's time-out must be 1 to 60000 ms (value: the time-out, limit: the longest)");
    static_assert(rule != Rule::RetriesOutOfRange, "the Modbus master retries at most 15 times (value, limit)");
    // NameInUse and CreateFailed come from the running node only.
    static constexpr bool passed = rule == Rule::None;
};

template <const app::Application& application>
struct ConfigurationCheck {
    static constexpr app::ConfigurationError error = app::findConfigurationError(application);
    static constexpr bool passed =
        ConfigurationRejected<error.kind, ObjectName(error.object), error.rule, error.value, error.limit>::passed;
};

} // namespace dcos::internal
