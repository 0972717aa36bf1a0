#include <sei/SeiNodeBackend.hpp>

#include <boot/ConfigurationStore.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <image/ImageHeader.hpp>
#include <sja1000/BitTiming.hpp>

namespace sei {

SeiIdentity SeiNodeBackend::identity()
{
    SeiIdentity identity;
    identity.nodeId = dcos::internal::localNode();
    identity.canNode = canNode_;
    identity.board = static_cast<uint8_t>(image::BoardType::Isa486);
    identity.serial = serial_;
    identity.versionText = versionText_;
    return identity;
}

SeiResult<SeiConfiguration> SeiNodeBackend::readConfiguration()
{
    const boot::StoredConfiguration stored = boot::ConfigurationStore::read(store_);
    if (!stored.readable || !stored.present) {
        return SeiStatus::CardError;
    }
    read_ = stored.configuration;
    SeiConfiguration configuration;
    configuration.sequence = read_.sequence;
    configuration.nodeId = read_.nodeId;
    configuration.bitRate = read_.canBitRate;
    configuration.queriesClosed = read_.queriesClosed();
    configuration.lockoutSeconds = read_.lockoutSeconds;
    configuration.commandLine = read_.commandLine;
    return configuration;
}

template <typename Change>
SeiResult<uint32_t> SeiNodeBackend::rewrite(Change change)
{
    const boot::StoredConfiguration stored = boot::ConfigurationStore::read(store_);
    if (!stored.readable || !stored.present) {
        // A node without a valid record has no keys either; it cannot be
        // here, but a record that went bad since the start is not replaced
        // by one made from nothing.
        return SeiStatus::CardError;
    }
    boot::ConfigurationBlock next = stored.configuration;
    change(next);
    uint32_t sequence = 0;
    if (!boot::ConfigurationStore::writeNext(store_, stored, next, sequence)) {
        return SeiStatus::CardError;
    }
    return sequence;
}

SeiResult<uint32_t> SeiNodeBackend::writeNodeId(uint16_t nodeId)
{
    return rewrite([nodeId](boot::ConfigurationBlock& block) { block.nodeId = nodeId; });
}

SeiResult<uint32_t> SeiNodeBackend::writeBitRate(uint32_t bitRate)
{
    return rewrite([bitRate](boot::ConfigurationBlock& block) { block.canBitRate = bitRate; });
}

bool SeiNodeBackend::bitRateValid(uint32_t bitRate)
{
    return sja1000::BitTimingCalculator::forBitRate(bitRate).ok();
}

} // namespace sei
