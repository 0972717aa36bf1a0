/*
 * Status SchedulerAgent::Yield() (seed 7.4): the round-robin step and
 * the switch to the next task of the same priority, in one pass.
 *
 * Yield is the primitive that is nothing but a context switch, so it is
 * written here, where the switch saves the callee-saved registers once: the
 * C++ version saved them in its own prologue and again in directSwitch. It
 * takes only the common case: the caller is not in an interrupt handler, no
 * dispatch hold is taken, the caller heads its ready queue and is ordered by
 * priority alone (rotatesOnYield), neither task carries work across a switch
 * (switchWork), the next one has nothing to be delivered and left through a
 * direct switch itself. Everything else goes to the C++ general path,
 * dcosYieldGeneral (Scheduler::yieldCurrent), with interrupts as they were.
 *
 * The parked stack has directSwitch's layout, four registers and a return
 * address, so any switch resumes a task parked here and this resumes any
 * task parked by directSwitch. The return address is yieldResumed, which
 * restores the flags saved at entry, so a task resumed from an interrupt's
 * exit (frameForDirectResume, interrupts off) gets its own flags back.
 *
 * Calling convention: -mregparm=3, no arguments (a static member); the Status is
 * returned in AL.
 */
#include <dcos/internal/YieldFastPath.h>

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
    pushl $yieldResumed
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

    /* A task parked above resumes here, whoever resumed it. */
yieldResumed:
1:  popfl
    xorl %eax, %eax                             /* STATUS_OK */
    ret

2:  popfl
    jmp SCHEDULER_YIELD_GENERAL                 /* Returns the Status to our caller. */

3:  movb $STATUS_IN_INTERRUPT, %al
    ret
    .size SCHEDULER_AGENT_YIELD, . - SCHEDULER_AGENT_YIELD

    .section .note.GNU-stack, "", @progbits
