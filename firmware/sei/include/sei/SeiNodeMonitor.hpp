// The monitoring stream's side in a running node (docs/protocols/monitor.md):
// what SeiMonitor needs of the node, on the kernel's public services. The
// console's copy, through the board's tap (bsp::setConsoleTap) into a
// static ring; this node's publications through the DSM agent; the stream's
// frames on the network link the Monitor request came from; and the
// SeiMonitorControl that SeiNodeBackend hands Monitor requests to. The
// system engineering interface agent's task
// (firmware/flash/src/FlashService.cpp) makes one of each.
#pragma once

#include <sei/SeiMonitor.hpp>
#include <sei/SeiMonitorControl.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

/// The node's console, copied into a static ring while a stream with the
/// console flag runs; each call holds interrupts off for one frame's bytes.
class NodeMonitorLog final : public MonitorLog {
public:
    void capture(bool on) override;
    size_t peek(uint8_t* out, size_t max) override;
    void consume(size_t count) override;
    uint32_t takeLost(uint32_t max) override;
    bool pending() override;
};

/// This node's publications, read through the DSM agent as any task reads
/// them (the agent's task is a super user, so it may read every one).
class NodeMonitorPages final : public MonitorPages {
public:
    uint8_t open(uint32_t publisher, uint32_t& subscription) override;
    void close(uint32_t subscription) override;
    bool read(uint32_t subscription, uint8_t (&page)[kSeiPageSize]) override;
};

/// The stream's frames, as single frames of type Monitoring on the link
/// the Monitor request came from.
class NodeMonitorSender final : public MonitorSender {
public:
    bool send(const MonitorTarget& target, const uint8_t* data, uint8_t length) override;
};

/// What SeiNodeBackend hands Monitor requests to: the stream, told where
/// the request being served came from (the task sets that before it hands
/// a frame to the configuration protocol's server, whose request completes
/// on that frame).
class NodeMonitorControl final : public SeiMonitorControl {
public:
    explicit NodeMonitorControl(SeiMonitor& monitor) : monitor_(monitor) {}

    void setRequestSource(const MonitorTarget& from) { from_ = from; }

    uint8_t configure(const SeiMessage& request, uint64_t nowNs) override
    {
        return monitor_.configure(request, from_, nowNs);
    }

private:
    SeiMonitor& monitor_;
    MonitorTarget from_;
};

} // namespace sei
