/*
 * Interrupt and exception entry stubs for all 256 IDT vectors.
 *
 * Every stub makes the stack look the same, so one C++ dispatcher serves all
 * vectors: exceptions that push no error code get a zero pushed in its
 * place, then the vector number is pushed (Intel SDM Vol. 3, 6.13 lists the
 * vectors that push an error code: 8, 10-14 and 17). The common path saves
 * the general and segment registers into an InterruptFrame, loads the kernel
 * data segments, and calls the board's line handler for an interrupt
 * controller line, interruptEntry(frame) for any other vector. At the exit
 * of the outermost interrupt the scheduler's hook returns the frame to
 * resume, which lets it switch to another task's saved frame.
 */
    .section .text
    .code32

.macro VECTOR_STUB number
    .align 8
vector_stub_\number:
    .if (\number == 8) || ((\number >= 10) && (\number <= 14)) || (\number == 17)
    .else
    pushl $0
    .endif
    pushl $\number
    jmp interrupt_common
.endm

    .globl interrupt_common
interrupt_common:
    pushal
    pushl %ds
    pushl %es
    pushl %fs
    pushl %gs
    /*
     * Ring 0 code runs with the kernel's data segments loaded, always, so
     * only an interrupt from a less privileged ring needs them reloaded; a
     * segment load costs some nine clocks on a 486 (the CPL is the low bits
     * of the interrupted CS, InterruptFrame::cs at offset 60).
     */
    testb $3, 60(%esp)
    jz 1f
    movl $0x10, %eax            /* Gdt::kernelData */
    movl %eax, %ds
    movl %eax, %es
    movl %eax, %fs
    movl %eax, %gs
1:  cld                         /* The C++ ABI expects DF clear. */
    /*
     * The interrupt controller's lines, vectors 32 to 47 (Idt.cpp checks the
     * numbers), go straight to the board's line handler with the line in
     * EAX (regparm): their latency is the one that counts, and a line
     * handler neither needs the frame nor returns one. The rest is what
     * interruptEntry does for every other vector: the nesting depth around
     * the handler, and at the outermost level's exit the hook that may
     * switch to another task's frame.
     */
    movl 48(%esp), %eax         /* InterruptFrame::vector */
    subl $32, %eax              /* the line: vector - firstIrqVector */
    cmpl $16, %eax
    jae 3f
    incl dcosInterruptDepth
    call *dcosInterruptLineHandler
    cmpl $1, dcosInterruptDepth /* The whole word: never 1 before task context. */
    jne 4f
    movl %esp, %eax             /* The frame to resume, for the hook to replace. */
    call *dcosOutermostExitHook
    movl %eax, %esp
4:  decl dcosInterruptDepth
    jmp interrupt_return
3:  movl %esp, %eax             /* InterruptFrame* argument, in EAX (regparm) */
    call interruptEntry
    movl %eax, %esp             /* Resume the frame the dispatcher chose. */
    .globl interrupt_return     /* Also the way into a frame for the scheduler's switch. */
interrupt_return:
    /* The same rule on the way back: a return to ring 0 finds the kernel's
       segments loaded and skips the four segment loads. */
    testb $3, 60(%esp)
    jnz 2f
    addl $16, %esp
    popal
    addl $8, %esp               /* Drop the vector number and error code. */
    iret
2:  popl %gs
    popl %fs
    popl %es
    popl %ds
    popal
    addl $8, %esp               /* Drop the vector number and error code. */
    iret

/*
 * Where a task parked from task context resumes when an interrupt's exit is
 * what picks it: through iret from the frame Scheduler::frameForDirectResume()
 * builds, whose EIP is this. The switch from task context
 * (dcos/src/scheduler/TaskContextSwitch.S) left on the task's stack the four
 * registers the C++ ABI has a call preserve, under a return address: they
 * are popped, and the return goes where that switch would have returned.
 */
    .globl directResume
directResume:
    popl %edi
    popl %esi
    popl %ebx
    popl %ebp
    ret

    /* .altmacro makes %vector pass the counter's value, not its name. */
    .altmacro
/*
 * void resumeInterruptFrame(InterruptFrame* frame): starts the first task by
 * "returning" into its initial frame; never returns.
 */
    .globl resumeInterruptFrame
resumeInterruptFrame:
    movl 4(%esp), %esp
    jmp interrupt_return

    .set vector, 0
    .rept 256
    VECTOR_STUB %vector
    .set vector, vector + 1
    .endr

/* The table of stub addresses Idt::install() reads. */
    .section .rodata
    .align 4
    .globl interruptStubTable
interruptStubTable:
.macro STUB_ADDRESS number
    .long vector_stub_\number
.endm
    .set vector, 0
    .rept 256
    STUB_ADDRESS %vector
    .set vector, vector + 1
    .endr
    .noaltmacro

/* The firmware has no executable stack; say so to the linker. */
    .section .note.GNU-stack, "", @progbits
