// The node's objects behind an application's Modbus register map: its DSM
// publishers and the I/O board's points (docs/protocols/modbus.md).
//
// ApplicationMapModel turns a request into page and point accesses; this
// backend makes them on the running node, in the line's task:
//
//   - a publisher is found by name the first time an entry names it, and
//     read through a subscription the line's task opens then (only a
//     subscription's owner may read it). A read takes the newest page when
//     there is one and otherwise the page it last saw, so a read never
//     waits; before the first Write the page is all zero, as the
//     publisher's own page is.
//   - a publisher with no writer task is written with DsmAgent::Write; the
//     application service has handed it to the line's task at boot, which
//     makes the line its single writer (seed 7.10).
//   - the I/O board is the device the service installed and opened at boot;
//     an analog input is converted (MfioClient, which waits in this task for
//     the conversion) and served as its 12-bit code, and the digital outputs
//     are read back and written as one word.
//
// Any refusal of the kernel or the board is answered ServerDeviceFailure
// (exception 04), counted, and kept as the last failure's status, which
// the console's `modbus state` shows.
#pragma once

#include <mbline/ApplicationMapModel.hpp>

#include <dcos/ApplicationDeclarations.hpp>
#include <dcos/ConfigurationRules.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace mbline {

class NodeMapBackend final : public MapBackend {
public:
    /// The backend's record of one publisher.
    struct Publisher {
        const char* name = nullptr;
        dcos::ObjectId publisher{};
        dcos::ObjectId subscription{};
        uint32_t lastSeenDataId = dcos::kNoDsmData;
        dcos::DsmPage page{};
    };

    /// Serves the I/O board @p board (null: none) from now on, and starts
    /// its failure count again. The subscriptions stay (closeSubscriptions).
    void useBoard(dcos::ObjectId board);

    modbus::ExceptionCode readPage(const char* publisher, dcos::DsmPage& page) override;
    modbus::ExceptionCode writePage(const char* publisher, const dcos::DsmPage& page) override;
    modbus::ExceptionCode readAnalogInput(uint32_t channel, uint16_t& counts) override;
    modbus::ExceptionCode readDigitalOutputs(uint16_t& outputs) override;
    modbus::ExceptionCode writeDigitalOutputs(uint16_t mask, uint16_t outputs) override;

    /// Closes the subscriptions the line's task opened (call it in that task).
    void closeSubscriptions();
    /// Asks the line's task to close them (from another task: only a
    /// subscription's owner may close it), and, in that task, does so when asked.
    void requestClose() { closeRequested_ = true; }
    void closeIfRequested()
    {
        if (closeRequested_) {
            closeRequested_ = false;
            closeSubscriptions();
        }
    }

    /// Accesses refused by the kernel or the board, and the last refusal's status.
    uint32_t failures() const { return failures_; }
    dcos::Status lastFailure() const { return lastFailure_; }

private:
    /// The record of @p name, found and subscribed on first use; null when
    /// the node has no such publisher or refuses the subscription.
    Publisher* find(const char* name);
    modbus::ExceptionCode fail(dcos::Status status);

    Publisher publishers_[dcos::app::kMaximumModbusMapEntries] = {};
    size_t count_ = 0;
    dcos::ObjectId board_{};
    uint32_t failures_ = 0;
    dcos::Status lastFailure_ = dcos::Status::Ok;
    volatile bool closeRequested_ = false;
};

} // namespace mbline
