// Build-time sizes of the kernel's static tables.
//
// Every table is reserved in full at build time; AddObjects activates slots
// in groups of eight up to these capacities. An image may override any of
// them with -D (the benchmark image raises them to 4096 to show that the
// real-time primitives cost the same with 8 objects as with 4096).
#pragma once

#include <stddef.h>
#include <stdint.h>

#ifndef DCOS_CONFIG_TASK_CAPACITY
#define DCOS_CONFIG_TASK_CAPACITY 256
#endif
#ifndef DCOS_CONFIG_TASKS_ACTIVE
#define DCOS_CONFIG_TASKS_ACTIVE 64
#endif
#ifndef DCOS_CONFIG_TIMER_CAPACITY
#define DCOS_CONFIG_TIMER_CAPACITY 256
#endif
#ifndef DCOS_CONFIG_TIMERS_ACTIVE
#define DCOS_CONFIG_TIMERS_ACTIVE 32
#endif
#ifndef DCOS_CONFIG_DEVICE_CAPACITY
#define DCOS_CONFIG_DEVICE_CAPACITY 64
#endif
// Every stack takes whole pages plus a guard page (StackArena.hpp): this
// arena gives every slot of the task table a stack of kMinimumStackSize
// (8 KiB each with its guard) besides the kernel's own tasks.
#ifndef DCOS_CONFIG_STACK_ARENA_KIB
#define DCOS_CONFIG_STACK_ARENA_KIB 2112
#endif
#ifndef DCOS_CONFIG_TIME_WHEEL_SLOTS
#define DCOS_CONFIG_TIME_WHEEL_SLOTS 257
#endif

#ifndef DCOS_CONFIG_SEMAPHORE_CAPACITY
#define DCOS_CONFIG_SEMAPHORE_CAPACITY 256
#endif
#ifndef DCOS_CONFIG_SEMAPHORES_ACTIVE
#define DCOS_CONFIG_SEMAPHORES_ACTIVE 32
#endif

namespace dcos::internal {

constexpr size_t kSemaphoreCapacity = DCOS_CONFIG_SEMAPHORE_CAPACITY;
constexpr size_t kSemaphoresActiveAtBoot = DCOS_CONFIG_SEMAPHORES_ACTIVE;
static_assert(kSemaphoresActiveAtBoot <= kSemaphoreCapacity && kSemaphoresActiveAtBoot % 8 == 0);

constexpr size_t kTaskCapacity = DCOS_CONFIG_TASK_CAPACITY;
constexpr size_t kTasksActiveAtBoot = DCOS_CONFIG_TASKS_ACTIVE;
constexpr size_t kTimerCapacity = DCOS_CONFIG_TIMER_CAPACITY;
constexpr size_t kTimersActiveAtBoot = DCOS_CONFIG_TIMERS_ACTIVE;
constexpr size_t kDeviceCapacity = DCOS_CONFIG_DEVICE_CAPACITY;
constexpr size_t kStackArenaBytes = size_t{DCOS_CONFIG_STACK_ARENA_KIB} * 1024;
constexpr size_t kTimeWheelSlots = DCOS_CONFIG_TIME_WHEEL_SLOTS;

static_assert(kTasksActiveAtBoot <= kTaskCapacity && kTasksActiveAtBoot % 8 == 0);

// The kernel's own tasks on every node: their names and stacks are part of
// what an application's configuration is checked against (ConfigurationRules.hpp).
// The root task, "console", starts the application and keeps the console
// shell, "shell", running: it starts the shell again if the shell ends.
constexpr const char* kIdleTaskName = "idle";
constexpr const char* kRootTaskName = "console";
constexpr const char* kShellTaskName = "shell";
constexpr size_t kIdleStackSize = 2048;
constexpr size_t kRootStackSize = 4096;
constexpr size_t kShellStackSize = 16384;
// The shell is the more urgent of the two, so it runs (and takes its life
// semaphore) as soon as the root task creates it.
constexpr uint8_t kShellTaskPriority = 24;
constexpr uint8_t kRootTaskPriority = 25;
// How often the root task starts the shell again before it gives up: a
// shell that ends at once every time would otherwise keep the node busy.
constexpr unsigned kShellRestartLimit = 8;
static_assert(kTimersActiveAtBoot <= kTimerCapacity && kTimersActiveAtBoot % 8 == 0);

} // namespace dcos::internal

// Message ports and distributed shared memory (seed 7.9, 7.10). A message
// buffer holds one queued 16-byte message; DCOS_CONFIG_MESSAGE_BUFFERS is the
// static reserve, of which AddMsgBufs activates more at run time.
#ifndef DCOS_CONFIG_PORT_CAPACITY
#define DCOS_CONFIG_PORT_CAPACITY 128
#endif
#ifndef DCOS_CONFIG_PORTS_ACTIVE
#define DCOS_CONFIG_PORTS_ACTIVE 32
#endif
#ifndef DCOS_CONFIG_MESSAGE_BUFFERS
#define DCOS_CONFIG_MESSAGE_BUFFERS 1024
#endif
#ifndef DCOS_CONFIG_MESSAGE_BUFFERS_ACTIVE
#define DCOS_CONFIG_MESSAGE_BUFFERS_ACTIVE 256
#endif
#ifndef DCOS_CONFIG_PUBLISHER_CAPACITY
#define DCOS_CONFIG_PUBLISHER_CAPACITY 128
#endif
#ifndef DCOS_CONFIG_PUBLISHERS_ACTIVE
#define DCOS_CONFIG_PUBLISHERS_ACTIVE 32
#endif
#ifndef DCOS_CONFIG_SUBSCRIPTION_CAPACITY
#define DCOS_CONFIG_SUBSCRIPTION_CAPACITY 256
#endif
#ifndef DCOS_CONFIG_SUBSCRIPTIONS_ACTIVE
#define DCOS_CONFIG_SUBSCRIPTIONS_ACTIVE 64
#endif

namespace dcos::internal {

constexpr size_t kPortCapacity = DCOS_CONFIG_PORT_CAPACITY;
constexpr size_t kPortsActiveAtBoot = DCOS_CONFIG_PORTS_ACTIVE;
constexpr size_t kMessageBufferCapacity = DCOS_CONFIG_MESSAGE_BUFFERS;
constexpr size_t kMessageBuffersActiveAtBoot = DCOS_CONFIG_MESSAGE_BUFFERS_ACTIVE;
constexpr size_t kPublisherCapacity = DCOS_CONFIG_PUBLISHER_CAPACITY;
constexpr size_t kPublishersActiveAtBoot = DCOS_CONFIG_PUBLISHERS_ACTIVE;
constexpr size_t kSubscriptionCapacity = DCOS_CONFIG_SUBSCRIPTION_CAPACITY;
constexpr size_t kSubscriptionsActiveAtBoot = DCOS_CONFIG_SUBSCRIPTIONS_ACTIVE;

static_assert(kPortsActiveAtBoot <= kPortCapacity && kPortsActiveAtBoot % 8 == 0);
static_assert(kMessageBuffersActiveAtBoot <= kMessageBufferCapacity);
static_assert(kPublishersActiveAtBoot <= kPublisherCapacity && kPublishersActiveAtBoot % 8 == 0);
static_assert(kSubscriptionsActiveAtBoot <= kSubscriptionCapacity && kSubscriptionsActiveAtBoot % 8 == 0);

} // namespace dcos::internal

// Buffer pools and segmented heaps (seed 7.7, 7.8). The areas come from the
// application; these are the sizes of the object tables only.
#ifndef DCOS_CONFIG_POOL_CAPACITY
#define DCOS_CONFIG_POOL_CAPACITY 64
#endif
#ifndef DCOS_CONFIG_POOLS_ACTIVE
#define DCOS_CONFIG_POOLS_ACTIVE 8
#endif
#ifndef DCOS_CONFIG_HEAP_CAPACITY
#define DCOS_CONFIG_HEAP_CAPACITY 64
#endif
#ifndef DCOS_CONFIG_HEAPS_ACTIVE
#define DCOS_CONFIG_HEAPS_ACTIVE 8
#endif

// The network interfaces manager's tables (seed 7.13): local interfaces,
// node-to-address mappings, neighbours' physical addresses and routes.
#ifndef DCOS_CONFIG_NETWORK_INTERFACES
#define DCOS_CONFIG_NETWORK_INTERFACES 4
#endif
#ifndef DCOS_CONFIG_NETWORK_NODE_ADDRESSES
#define DCOS_CONFIG_NETWORK_NODE_ADDRESSES 64
#endif
#ifndef DCOS_CONFIG_NETWORK_NEIGHBOURS
#define DCOS_CONFIG_NETWORK_NEIGHBOURS 64
#endif
#ifndef DCOS_CONFIG_NETWORK_ROUTES
#define DCOS_CONFIG_NETWORK_ROUTES 16
#endif

// The remote agent (seed 6.4): transactions a node's tasks may have under
// way at once, requests it remembers as served (to answer a retransmission
// without executing it again), the tasks that serve them, and the
// watchdog: a silent peer is asked again every watchdog period, and given
// up after that many silent periods in a row.
#ifndef DCOS_CONFIG_REMOTE_CALLS
#define DCOS_CONFIG_REMOTE_CALLS 16
#endif
#ifndef DCOS_CONFIG_REMOTE_SERVED
#define DCOS_CONFIG_REMOTE_SERVED 32
#endif
#ifndef DCOS_CONFIG_REMOTE_WORKERS
#define DCOS_CONFIG_REMOTE_WORKERS 2
#endif
#ifndef DCOS_CONFIG_REMOTE_WATCHDOG_MS
#define DCOS_CONFIG_REMOTE_WATCHDOG_MS 50
#endif
#ifndef DCOS_CONFIG_REMOTE_SILENT_PERIODS
#define DCOS_CONFIG_REMOTE_SILENT_PERIODS 4
#endif

// Publications over the network (seed 7.10): the other nodes' publishers
// this node's tasks may hold subscriptions to at once. Each keeps the
// latest page received, with one reassembly per interface.
#ifndef DCOS_CONFIG_REMOTE_PUBLISHERS
#define DCOS_CONFIG_REMOTE_PUBLISHERS 16
#endif

namespace dcos::internal {

constexpr size_t kRemotePublishers = DCOS_CONFIG_REMOTE_PUBLISHERS;
static_assert(kRemotePublishers >= 1 && kRemotePublishers <= 255, "DCOS_CONFIG_REMOTE_PUBLISHERS: 1 to 255");

constexpr size_t kRemoteCalls = DCOS_CONFIG_REMOTE_CALLS;
constexpr size_t kRemoteServed = DCOS_CONFIG_REMOTE_SERVED;
constexpr size_t kRemoteWorkers = DCOS_CONFIG_REMOTE_WORKERS;
constexpr uint32_t kRemoteWatchdogMs = DCOS_CONFIG_REMOTE_WATCHDOG_MS;
constexpr unsigned kRemoteSilentPeriods = DCOS_CONFIG_REMOTE_SILENT_PERIODS;
// A transaction number is the call slot in its low four bits and a
// generation in the high four (docs/protocols/remote-transactions.md).
static_assert(kRemoteCalls >= 1 && kRemoteCalls <= 16, "DCOS_CONFIG_REMOTE_CALLS: 1 to 16");
static_assert(kRemoteServed >= kRemoteWorkers && kRemoteServed <= 255, "DCOS_CONFIG_REMOTE_SERVED: workers to 255");
static_assert(kRemoteWorkers >= 1 && kRemoteWorkers <= 8, "DCOS_CONFIG_REMOTE_WORKERS: 1 to 8");
static_assert(kRemoteWatchdogMs >= 1 && kRemoteSilentPeriods >= 1);

constexpr size_t kNetworkInterfaces = DCOS_CONFIG_NETWORK_INTERFACES;
constexpr size_t kNetworkNodeAddresses = DCOS_CONFIG_NETWORK_NODE_ADDRESSES;
constexpr size_t kNetworkNeighbours = DCOS_CONFIG_NETWORK_NEIGHBOURS;
constexpr size_t kNetworkRoutes = DCOS_CONFIG_NETWORK_ROUTES;

constexpr size_t kPoolCapacity = DCOS_CONFIG_POOL_CAPACITY;
constexpr size_t kPoolsActiveAtBoot = DCOS_CONFIG_POOLS_ACTIVE;
constexpr size_t kHeapCapacity = DCOS_CONFIG_HEAP_CAPACITY;
constexpr size_t kHeapsActiveAtBoot = DCOS_CONFIG_HEAPS_ACTIVE;

static_assert(kPoolsActiveAtBoot <= kPoolCapacity && kPoolsActiveAtBoot % 8 == 0 && kPoolsActiveAtBoot != 0);
static_assert(kHeapsActiveAtBoot <= kHeapCapacity && kHeapsActiveAtBoot % 8 == 0 && kHeapsActiveAtBoot != 0);

} // namespace dcos::internal
