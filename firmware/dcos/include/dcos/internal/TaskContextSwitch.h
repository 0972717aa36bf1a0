/*
 * What the scheduler's assembly (scheduler/TaskContextSwitch.S: the switch
 * from task context and Yield's fast path) knows of the kernel's C++ objects: field offsets in a Task, the scheduler's and the
 * interrupt table's static members by their linkage names, and status
 * codes. Plain defines, so that the assembler and the compiler read the
 * same file; Scheduler.cpp checks every value against the C++ layout at
 * compile time, and a wrong name fails the link.
 */
#pragma once

/* Offsets in dcos::internal::Task. */
#define TASK_READY_NEXT 4          /* IntrusiveListNode<ReadyQueueTag>::next_ (the node is the first base) */
#define TASK_PRIORITY 71
#define TASK_SAVED_FRAME 84
#define TASK_RESUME_STACK 88
/*
 * Three adjacent bytes, so that one compare tests two of them:
 * switchWork, rotatesOnYield, deliveryPending.
 */
#define TASK_SWITCH_WORK 668
#define TASK_ROTATES_ON_YIELD 669
#define TASK_DELIVERY_PENDING 670

/* Static members, by their mangled names. */
#define SCHEDULER_CURRENT _ZN4dcos8internal9Scheduler8current_E
#define SCHEDULER_DISPATCH_HOLDS _ZN4dcos8internal9Scheduler14dispatchHolds_E
#define SCHEDULER_SWITCH_COUNT _ZN4dcos8internal9Scheduler12switchCount_E
#define SCHEDULER_READY_QUEUES _ZN4dcos8internal9Scheduler12readyQueues_E
#define IDT_NESTING_DEPTH dcosInterruptDepth /* Idt::depth_; non-zero outside task context too */

/* dcos::SchedulerAgent::Yield(), a static member, and the C++ general path it falls back to. */
#define SCHEDULER_AGENT_YIELD _ZN4dcos14SchedulerAgent5YieldEv
#define SCHEDULER_YIELD_GENERAL dcosYieldGeneral

/* The switch from task context, called from C++ (Scheduler::switchDirectly). */
#define SCHEDULER_SWITCH_FROM_TASK dcosSwitchFromTask

/* dcos::Status values. */
#define STATUS_OK 0
#define STATUS_IN_INTERRUPT 11
