/*
 * The switch from task context (seed 7.4), in the two places every
 * instruction of it counts: Scheduler::switchDirectly, the switch a task
 * makes when it blocks, yields or readies a more urgent task, and the whole
 * of Yield's common case.
 *
 * A task parked here leaves on its stack its caller's flags, then the
 * address of taskResumed, then the four registers the C++ ABI has a call
 * preserve. Either routine here resumes a task parked by either: it pops
 * the registers and returns into taskResumed, which restores the flags the
 * task had when it called; so does directResume (InterruptStubs.S), the
 * entry of a frame an interrupt's exit builds for it (frameForDirectResume).
 * Saving the flags here, rather than in the C++ caller, lets that caller
 * jump here as its last act instead of calling, so no C++ frame stays on a
 * parked task's stack: the C++ version saved the callee-saved registers
 * twice, in its own prologue and again in the assembly it called.
 */
#include <dcos/internal/TaskContextSwitch.h>

/*
 * Status SchedulerAgent::Yield(): the round-robin step and the switch to
 * the next task of the same priority, in one pass. It takes only the common
 * case: the caller is not in an interrupt handler, no dispatch hold is
 * taken, the caller heads its ready queue and is ordered by priority alone
 * (rotatesOnYield), neither task carries work across a switch (switchWork),
 * the next one has nothing to be delivered and left through a direct switch
 * itself. Everything else goes to the C++ general path, dcosYieldGeneral
 * (Scheduler::yieldCurrent), with interrupts as they were.
 *
 * Calling convention: -mregparm=3, no arguments (a static member); the
 * Status is returned in AL.
 */
    /* The section name the linker script keeps for the agents' interface. */
    .section .text._ZN4dcos14SchedulerAgent5YieldEv, "ax", @progbits
    .code32

    .globl SCHEDULER_AGENT_YIELD
    .type SCHEDULER_AGENT_YIELD, @function
SCHEDULER_AGENT_YIELD:
    cmpl $0, IDT_NESTING_DEPTH
    jne 3f                                      /* Not from an interrupt handler. */
    pushfl
    cli
    movl SCHEDULER_CURRENT, %ecx
    /* switchWork clear and rotatesOnYield set, in one compare. */
    cmpw $0x0100, TASK_SWITCH_WORK(%ecx)
    jne 2f
    cmpl $0, SCHEDULER_DISPATCH_HOLDS
    jne 2f
    movzbl TASK_PRIORITY(%ecx), %edx
    leal SCHEDULER_READY_QUEUES(, %edx, 4), %edx /* The caller's ready ring. */
    cmpl %ecx, (%edx)
    jne 2f                                      /* Not at its head. */
    movl TASK_READY_NEXT(%ecx), %eax            /* The next of its equals. */
    cmpl %eax, %ecx
    je 1f                                       /* Alone at its priority: runs on. */
    /* The next one's switchWork and deliveryPending, in one test. */
    testl $0x00FF00FF, TASK_SWITCH_WORK(%eax)
    jne 2f
    cmpl $0, TASK_RESUME_STACK(%eax)
    je 2f                                       /* Preempted: resumes from a frame. */
    movl %eax, (%edx)                           /* The ring's step: next heads it. */
    movl %eax, SCHEDULER_CURRENT
    incl SCHEDULER_SWITCH_COUNT
    pushl $taskResumed
    pushl %ebp
    pushl %ebx
    pushl %esi
    pushl %edi
    movl %esp, TASK_RESUME_STACK(%ecx)
    movl TASK_RESUME_STACK(%eax), %esp
    movl $0, TASK_RESUME_STACK(%eax)
    popl %edi
    popl %esi
    popl %ebx
    popl %ebp
    ret                                         /* Into the next task's own switch. */

1:  popfl
    xorl %eax, %eax                             /* STATUS_OK */
    ret

2:  popfl
    jmp SCHEDULER_YIELD_GENERAL                 /* Returns the Status to our caller. */

3:  movb $STATUS_IN_INTERRUPT, %al
    ret
    .size SCHEDULER_AGENT_YIELD, . - SCHEDULER_AGENT_YIELD

/*
 * void dcosSwitchFromTask(uint32_t** save, Task* next, uint32_t flags),
 * regparm(3): EAX = &previous->resumeStack, EDX = next, ECX = the flags to
 * restore when previous runs again. Interrupts are disabled; current_ and
 * the switch count are already updated. Returns to the caller's caller (the
 * C++ side jumps here) when previous is resumed.
 */
    .section .text.dcos_switch_from_task, "ax", @progbits
    .globl SCHEDULER_SWITCH_FROM_TASK
    .type SCHEDULER_SWITCH_FROM_TASK, @function
SCHEDULER_SWITCH_FROM_TASK:
    pushl %ecx
    pushl $taskResumed
    pushl %ebp
    pushl %ebx
    pushl %esi
    pushl %edi
    movl %esp, (%eax)
    movl TASK_RESUME_STACK(%edx), %eax
    testl %eax, %eax
    jz 1f                                       /* Preempted: resumes from a frame. */
    movl $0, TASK_RESUME_STACK(%edx)
    movl %eax, %esp
    popl %edi
    popl %esi
    popl %ebx
    popl %ebp
    ret                                         /* Into the next task's own switch. */
1:  movl TASK_SAVED_FRAME(%edx), %esp
    jmp interrupt_return
    .size SCHEDULER_SWITCH_FROM_TASK, . - SCHEDULER_SWITCH_FROM_TASK

/*
 * Where a task parked by either routine above resumes, whoever resumed it.
 * Yield returns a Status in AL, Ok: EAX holds whatever the resuming side
 * left in it, so it is cleared here; the C++ side's switch returns nothing
 * and does not mind.
 */
    .section .text.dcos_task_resumed, "ax", @progbits
taskResumed:
    popfl
    xorl %eax, %eax                             /* STATUS_OK */
    ret

    .section .note.GNU-stack, "", @progbits
