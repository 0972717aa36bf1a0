// The real-time services' inline lookups (ObjectTable::find) compare the
// whole id with the one a slot keeps, 0 while the slot is free. Neither the
// null id nor the all-ones id (type 15, reserved, so only ever forged) may
// reach a free slot through them: each agent's fast path must hand both to
// its complete service, which refuses them. Full test image only: the
// minimal kernel configuration leaves these agents out.
#include "KernelTestSupport.hpp"

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;

bool oddIdsOnFastPaths(shell::Shell& shell)
{
    bool ok = true;
    const ObjectId oddIds[] = {ObjectId::null(), ObjectId::fromRaw(0xFFFFFFFFu)};
    for (const ObjectId odd : oddIds) {
        const Status expected = odd.isNull() ? Status::InvalidId : Status::WrongType;
        dcos::Message message{};
        dcos::DsmPage page{};
        uint8_t bytes[16];
        ok = checkStatus(shell, dcos::semaphoreAgent.Acquire(odd, dcos::kPoll), expected, "Acquire of an odd id") && ok;
        ok = checkStatus(shell, dcos::semaphoreAgent.Release(odd), expected, "Release of an odd id") && ok;
        ok = checkStatus(shell, dcos::messagePortAgent.Send(odd, message, 0), expected, "Send to an odd id") && ok;
        ok = checkStatus(shell, dcos::messagePortAgent.Receive(odd, message, dcos::kPoll), expected,
                         "Receive from an odd id") && ok;
        ok = checkStatus(shell, dcos::dsmAgent.Write(odd, page).status(), expected, "Write to an odd id") && ok;
        ok = checkStatus(shell, dcos::dsmAgent.Read(odd, dcos::kNoDsmData, page, dcos::kPoll).status(), expected,
                         "Read through an odd id") && ok;
        ok = checkStatus(shell, dcos::bufferPoolAgent.Allocate(odd).status(), expected, "Allocate from an odd pool")
             && ok;
        ok = checkStatus(shell, dcos::bufferPoolAgent.Return(odd, bytes), expected, "Return to an odd pool") && ok;
        ok = checkStatus(shell, dcos::heapAgent.Allocate(odd, 8).status(), expected, "Allocate from an odd heap") && ok;
        ok = checkStatus(shell, dcos::heapAgent.Return(odd, bytes), expected, "Return to an odd heap") && ok;
    }
    return ok;
}

} // namespace

DCOS_TARGET_TEST(oddIdTest, "oddids", "the null and the all-ones id are refused on every real-time fast path",
                 oddIdsOnFastPaths);

} // namespace target_test
