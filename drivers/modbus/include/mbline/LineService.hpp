// What the two Modbus lines' application services share: the slave's on
// COM2 (ModbusCommands.cpp) and the polling master's on COM3 (PollLine.cpp).
//
// Each runs in the root task while the loader holds dispatching, after
// every object of the application exists: it hands the publishers its line
// writes to its line's task (a publisher has a single writer, seed 7.10),
// and brings its port up with the declared settings.
#pragma once

#include <dcos/ApplicationDeclarations.hpp>
#include <dcos/ConfigurationRules.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <runtime/Text.hpp>

#include <bsp/Uart16550.hpp>

#include <stddef.h>

namespace mbline {

/// The port's settings for a Modbus line: 8 data bits, a receive trigger of
/// one byte and the driver enable on RTS (docs/protocols/modbus.md, "The
/// port"). [SL] 2.5.1: no parity takes a second stop bit, so that a
/// character stays 11 bits.
bsp::UartSettings lineSettings(uint32_t baud, dcos::app::ModbusParity parity);

/// The letter of @p parity in a line's settings, as in 8E1.
constexpr char parityLetter(bsp::UartParity parity)
{
    return parity == bsp::UartParity::None ? 'N' : parity == bsp::UartParity::Odd ? 'O' : 'E';
}

/// A service's refusal: the loader names the application's @p kind (its
/// slave or master), the rule and the status, and deletes the application.
inline dcos::app::ConfigurationError refusedBy(const dcos::app::Application& application, dcos::app::ObjectKind kind,
                                               dcos::Status status)
{
    return dcos::app::rules::broken(dcos::app::ConfigurationRule::CreateFailed, kind, application.name,
                                    static_cast<size_t>(status));
}

/// Hands to @p task each publisher named by an entry of @p list that
/// @p writes(entry) says the line writes; a publisher named by several such
/// entries is handed over once. The first refusal is returned.
template <class Entry, class Writes>
dcos::Status handOverPublishers(const dcos::app::DeclarationList<Entry>& list, Writes writes, dcos::ObjectId task)
{
    for (size_t i = 0; i < list.count; ++i) {
        if (!writes(list[i])) {
            continue;
        }
        bool handed = false;
        for (size_t j = 0; j < i && !handed; ++j) {
            handed = writes(list[j]) && runtime::textEquals(list[j].object, list[i].object);
        }
        if (handed) {
            continue;
        }
        const dcos::Result<dcos::ObjectId> publisher = dcos::dsmAgent.NameToObject(list[i].object);
        const dcos::Status transferred =
            publisher.ok() ? dcos::dsmAgent.XferOwnership(publisher.value(), task) : publisher.status();
        if (transferred != dcos::Status::Ok) {
            return transferred;
        }
    }
    return dcos::Status::Ok;
}

} // namespace mbline
