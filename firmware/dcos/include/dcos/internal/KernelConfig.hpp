// Build-time sizes of the kernel's static tables.
//
// Every table is reserved in full at build time; AddObjects activates slots
// in groups of eight up to these capacities. An image may override any of
// them with -D (the benchmark image raises them to 4096 to show that the
// real-time primitives cost the same with 8 objects as with 4096).
#pragma once

#include <stddef.h>

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
#ifndef DCOS_CONFIG_STACK_ARENA_KIB
#define DCOS_CONFIG_STACK_ARENA_KIB 1024
#endif
#ifndef DCOS_CONFIG_TIME_WHEEL_SLOTS
#define DCOS_CONFIG_TIME_WHEEL_SLOTS 257
#endif

namespace dcos::internal {

constexpr size_t kTaskCapacity = DCOS_CONFIG_TASK_CAPACITY;
constexpr size_t kTasksActiveAtBoot = DCOS_CONFIG_TASKS_ACTIVE;
constexpr size_t kTimerCapacity = DCOS_CONFIG_TIMER_CAPACITY;
constexpr size_t kTimersActiveAtBoot = DCOS_CONFIG_TIMERS_ACTIVE;
constexpr size_t kStackArenaBytes = size_t{DCOS_CONFIG_STACK_ARENA_KIB} * 1024;
constexpr size_t kTimeWheelSlots = DCOS_CONFIG_TIME_WHEEL_SLOTS;

static_assert(kTasksActiveAtBoot <= kTaskCapacity && kTasksActiveAtBoot % 8 == 0);
static_assert(kTimersActiveAtBoot <= kTimerCapacity && kTimersActiveAtBoot % 8 == 0);

} // namespace dcos::internal
