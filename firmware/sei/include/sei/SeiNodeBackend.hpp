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
#include <sei/SeiMonitorControl.hpp>

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
    SeiResult<uint32_t> writeConfiguration(const SeiConfiguration& configuration) override;
    bool queriesClosed() override;
    void activateBitRate(uint16_t delayMs, uint64_t nowNs) override;

    uint8_t listObjects(uint8_t type, uint16_t first, SeiMessage& reply) override;
    uint8_t findObject(uint8_t type, const char* name, uint8_t length, uint32_t& id) override;
    uint8_t objectInfo(uint32_t id, SeiMessage& reply) override;
    uint8_t nodeStatistics(SeiMessage& reply) override;
    uint8_t createTask(const SeiMessage& request, uint32_t& id) override;
    uint8_t startTask(uint32_t id) override;
    uint8_t stopTask(uint32_t id) override;
    uint8_t killTask(uint32_t id) override;
    uint8_t createObject(const SeiMessage& request, uint32_t& id) override;
    uint8_t deleteObject(uint32_t id) override;
    uint8_t addObjects(uint8_t type, uint16_t count) override;
    uint8_t monitor(const SeiMessage& request, uint64_t nowNs) override;

    /// Where Monitor requests go; without one they are refused (NotSupported).
    void setMonitor(SeiMonitorControl* monitor) { monitor_ = monitor; }

    /// The agent's task calls this whenever it wakes: a bit-rate switch
    /// that ActivateBitRate asked for is made once its time has come.
    void poll(uint64_t nowNs);
    /// When poll() has work next (a pending switch), or UINT64_MAX.
    uint64_t nextDeadlineNs() const { return switchAtNs_; }

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
    // Whether the queries are closed, as the record last read or written
    // says; until the first read, unknown.
    bool queriesClosed_ = true;
    bool queriesKnown_ = false;
    SeiMonitorControl* monitor_ = nullptr;
    // ActivateBitRate's switch: when (UINT64_MAX for none) and to what.
    uint64_t switchAtNs_ = UINT64_MAX;
    uint32_t switchRate_ = 0;
    // ListObjects' and ObjectInfo's names: the reply points into these.
    char names_[kSeiMaxListEntries][kSeiMaxName + 1] = {};
};

} // namespace sei
