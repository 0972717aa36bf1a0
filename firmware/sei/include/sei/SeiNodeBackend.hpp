// The configuration protocol's backend in a running node (SeiBackend.hpp):
// the node's identity from the kernel and the card, the card's
// configuration record read and written through boot::ConfigurationStore
// (the next record into the older copy, so a power cut leaves the old one).
// Written for the system engineering interface agent's task
// (firmware/flash/src/FlashService.cpp), which holds the card
// (dcos/internal/FlashServiceHooks.hpp, CardHold) around every request, so
// a read, change and write of the record never interleaves with a flash
// session's writes or the boot command's.
#pragma once

#include <sei/SeiBackend.hpp>

#include <boot/ConfigurationBlock.hpp>
#include <boot/SectorStore.hpp>

#include <stdint.h>

namespace sei {

class SeiNodeBackend final : public SeiBackend {
public:
    /// Serves the node on @p store with the serial number @p serial (the
    /// configuration's at start) and the running image's @p versionText.
    SeiNodeBackend(boot::SectorStore& store, uint32_t serial, const char* versionText)
        : store_(store), serial_(serial), versionText_(versionText)
    {
    }

    /// The CAN node number the node answers as now (the interface's).
    void setCanNode(uint8_t canNode) { canNode_ = canNode; }

    SeiIdentity identity() override;
    SeiResult<SeiConfiguration> readConfiguration() override;
    SeiResult<uint32_t> writeNodeId(uint16_t nodeId) override;
    SeiResult<uint32_t> writeBitRate(uint32_t bitRate) override;
    bool bitRateValid(uint32_t bitRate) override;
    SeiStatus prepareRestart() override { return SeiStatus::Ok; }

private:
    // Reads the record, lets @p change alter it, writes it as the next one.
    template <typename Change>
    SeiResult<uint32_t> rewrite(Change change);

    boot::SectorStore& store_;
    uint32_t serial_;
    const char* versionText_;
    uint8_t canNode_ = 0xFF;
    // The last record read: GetConfiguration's command line points into it.
    boot::ConfigurationBlock read_;
};

} // namespace sei
