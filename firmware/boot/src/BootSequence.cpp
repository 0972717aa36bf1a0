#include <boot/BootSequence.hpp>

namespace boot {

bool BootSequence::writeNext(SectorStore& store, BootDecision& decision, unsigned copy)
{
    // The next sequence, into the copy that does not hold the state read: a
    // power cut during this write leaves that state standing.
    decision.plan.state.sequence = decision.hadState ? decision.stored.sequence + 1 : 1;
    uint8_t record[card::kSectorSize];
    decision.plan.state.encode(record);
    return store.write(card::kBootStateLba + (decision.hadState ? copy ^ 1u : 0u), 1, record);
}

} // namespace boot
