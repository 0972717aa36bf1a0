/*
 * Entry points of the fault tasks and the recovery entry (FaultTasks.hpp).
 *
 * A task gate switches to the fault task's TSS and pushes the error code on
 * its stack (Intel SDM Vol. 3, 6.12.2). The stub hands vector and error code
 * to faultTaskMain, then IRET, with EFLAGS.NT set by the task switch, returns
 * to the interrupted task through the TSS back link. The processor saves
 * this task's EIP after the IRET, so the next fault resumes at the JMP and
 * starts over; its ESP is saved back at the top of its stack.
 */
    .section .text
    .code32

    .globl pageFaultTaskEntry
pageFaultTaskEntry:
    pushl $14                   /* #PF; the error code is already pushed */
    call faultTaskMain
    addl $8, %esp               /* vector and error code */
    iret
    jmp pageFaultTaskEntry

    .globl doubleFaultTaskEntry
doubleFaultTaskEntry:
    pushl $8                    /* #DF; its error code is always 0 */
    call faultTaskMain          /* Panics; never returns. */
1:  cli
    hlt
    jmp 1b

/*
 * Runs in the main TSS on the recovery stack, with ESP pointing at the
 * InterruptFrame the page-fault task built: the same path a fault taken
 * through an interrupt gate would have followed.
 */
    .globl faultRecoveryEntry
faultRecoveryEntry:
    movl %esp, %eax             /* InterruptFrame* argument, in EAX (regparm) */
    call interruptEntry
    pushl %eax                  /* the frame to resume */
    call faultRecoveryFinished
    call resumeInterruptFrame   /* never returns */

/* The firmware has no executable stack; say so to the linker. */
    .section .note.GNU-stack, "", @progbits
