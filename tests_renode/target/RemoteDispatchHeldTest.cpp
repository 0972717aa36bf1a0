// A remote call made while the caller holds dispatch (the application
// loader does, while it creates an application): refused at once, never
// blocked. A task that holds dispatch cannot block, so a call that had to
// wait for a reply would return at once and leave the caller in the call
// slot's wait queue, where a later reply would wake it instead of its own
// caller. Runs where the remote agent is up from boot: on the dual-Pentium
// board, whose shared-memory network attaches at boot
// (tests_renode/test_board_p5smp.py).
#include "KernelTestSupport.hpp"
#include "TargetTest.hpp"

#include <bsp/Board.hpp>
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/Scheduler.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;

// Whether this node has the dual-Pentium board's shared-memory interface.
bool sharedMemoryUp()
{
    for (size_t interface = 0; interface < dcos::internal::kNetworkInterfaces; ++interface) {
        const dcos::Result<dcos::NetworkInterface> entry =
            dcos::NetworkInterfacesManager::GetInterface(static_cast<uint8_t>(interface));
        if (entry.ok() && entry.value().kind == dcos::InterfaceKind::SharedMemory) {
            return true;
        }
    }
    return false;
}

bool remoteWithDispatchHeld(shell::Shell& shell)
{
    if (!sharedMemoryUp()) {
        return check(shell, false, "the shared-memory network is up (this test runs on the dual-Pentium board)");
    }
    // The board's other node (2 and 3 by default), and a semaphore index it
    // never issued: the answer, once asked, is that node's, and not "ok".
    const uint16_t other = bsp::nodeId() == 2 ? 3 : 2;
    const ObjectId far(other, dcos::ObjectType::Semaphore, 0xFFE);
    const uint64_t before = dcos::timerAgent.Uptime();
    dcos::internal::Scheduler::holdDispatch();
    const Status held = dcos::semaphoreAgent.GetCount(far).status();
    const Status heldName = dcos::semaphoreAgent.NameToObject("no-such-name").status();
    dcos::internal::Scheduler::releaseDispatch();
    const uint64_t heldNs = dcos::timerAgent.Uptime() - before;
    bool ok = checkStatus(shell, held, Status::Deadlock, "a remote primitive with dispatch held is refused");
    ok = checkStatus(shell, heldName, Status::NotFound, "a name query with dispatch held answers from this node") && ok;
    // Neither waited: the watchdog's silent periods are 200 ms.
    ok = check(shell, heldNs < 10'000'000, "neither call waited for the other node") && ok;
    // Dispatch released, the same call crosses to the other node, which answers for itself.
    const Status asked = dcos::semaphoreAgent.GetCount(far).status();
    ok = check(shell, asked != Status::Deadlock && asked != Status::Unreachable && asked != Status::Ok,
               "the same call, dispatch released, gets the other node's answer") && ok;
    return ok;
}

DCOS_TARGET_TEST(remoteDispatchHeldTest, "remoteheld", "a remote call with dispatch held is refused, never blocked",
                 remoteWithDispatchHeld);

} // namespace

} // namespace target_test
