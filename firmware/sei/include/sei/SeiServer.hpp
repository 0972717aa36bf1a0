// The node's side of the configuration protocol (docs/protocols/config.md):
// takes requests, one at a time, performs them on a SeiBackend and
// answers them. Whatever carries the messages (CanSeiServer on CAN) hands
// every whole request to handle() and sends the reply it writes.
//
// The server also holds the node's part in a scan: whether it is the
// selected node, which a Select of its serial number makes it and a
// Select of another one or a Deselect ends. On CAN the selected node
// answers on the broadcast address too ("Scanning"); which address a
// request came to is the transport's business, so the scanning commands
// mean the same here whatever address they came to.
#pragma once

#include <sei/SeiAuthenticator.hpp>
#include <sei/SeiBackend.hpp>
#include <sei/SeiMessage.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

class SeiServer {
public:
    /// The node ids SetNodeId takes: those a CAN node number can carry
    /// (255 is the broadcast address, and 0 in the configuration means the
    /// kernel's default).
    static constexpr uint16_t kMinNodeId = 1;
    static constexpr uint16_t kMaxNodeId = 254;

    /// Serves @p backend; @p authenticator checks the MACs (it was given
    /// the node id and serial number of the backend's identity).
    SeiServer(SeiBackend& backend, SeiAuthenticator& authenticator)
        : backend_(backend), authenticator_(authenticator)
    {
    }

    /// Answers one request of @p length bytes at @p nowNs; the reply's
    /// length, or 0 when there is nothing to send: a ProbeSerial or Select
    /// that does not match this node, a Deselect, or a @p capacity too
    /// small for the reply (kSeiMaxMessage always fits).
    size_t handle(const uint8_t* request, size_t length, uint8_t* reply, size_t capacity, uint64_t nowNs);

    /// True once a Restart was answered Ok: the caller sends the reply and
    /// then restarts the node.
    bool restartRequested() const { return restartRequested_; }
    /// Whether this node is the selected one.
    bool selected() const { return selected_; }

    /// ProbeSerial's rule: a node answers when its serial number is not 0
    /// and its top @p bits bits are @p value's.
    static bool probeMatches(uint32_t serial, uint8_t bits, uint32_t value)
    {
        return serial != 0 && (serial & seiProbeMask(bits)) == value;
    }

private:
    /// What performing a request did: its reply's status, or no reply.
    struct Outcome {
        bool answer = true;
        SeiStatus status = SeiStatus::Ok;
    };

    Outcome perform(const SeiMessage& request, const uint8_t* bytes, size_t length, uint64_t nowNs,
                    SeiMessage& reply);
    SeiStatus identify(uint64_t nowNs, SeiMessage& reply);
    SeiStatus getConfiguration(const SeiMessage& request, const uint8_t* bytes, size_t length, uint64_t nowNs,
                               SeiMessage& reply);
    SeiStatus setNodeId(const SeiMessage& request, SeiMessage& reply);
    SeiStatus setBitRate(const SeiMessage& request, SeiMessage& reply);
    SeiStatus restart();
    SeiStatus setConfiguration(const SeiMessage& request, SeiMessage& reply);
    // The object queries and management commands, once admitted.
    SeiStatus manage(const SeiMessage& request, uint64_t nowNs, SeiMessage& reply);
    // A query: Ok when it may be answered (its MAC right, or none needed).
    SeiStatus admitQuery(const SeiMessage& request, const uint8_t* bytes, size_t length, uint64_t nowNs);
    Outcome select(const SeiMessage& request, SeiMessage& reply);
    SeiStatus authenticate(const SeiMessage& request, const uint8_t* bytes, size_t length, uint64_t nowNs);

    SeiBackend& backend_;
    SeiAuthenticator& authenticator_;
    bool restartRequested_ = false;
    bool selected_ = false;
};

} // namespace sei
