// Host-test definitions of the kernel context (see FakeKernelContext.hpp).
#include "FakeKernelContext.hpp"

#include <dcos/internal/KernelContext.hpp>

namespace {

struct Context {
    dcos::ObjectId task{dcos::fake::kDefaultNode, dcos::ObjectType::Task, 1};
    bool superUser = false;
    bool inInterrupt = false;
    uint16_t node = dcos::fake::kDefaultNode;
};

Context context;

} // namespace

namespace dcos::fake {

void reset()
{
    context = Context{};
}

void playSuperUser(ObjectId task)
{
    context.task = task;
    context.superUser = true;
}

void playUserTask(ObjectId task)
{
    context.task = task;
    context.superUser = false;
}

void setInInterrupt(bool inInterrupt)
{
    context.inInterrupt = inInterrupt;
}

void setLocalNode(uint16_t node)
{
    context.node = node;
}

} // namespace dcos::fake

namespace dcos::internal {

ObjectId currentTaskId()
{
    return context.task;
}

bool currentTaskIsSuperUser()
{
    return context.superUser;
}

bool inInterruptContext()
{
    return context.inInterrupt;
}

uint16_t localNode()
{
    return context.node;
}

// Host tests have no task table; any key below the count does, because the
// tables compare owners exactly.
size_t taskSlotOf(ObjectId task)
{
    return task.index() & (kTaskCapacity - 1);
}

} // namespace dcos::internal
