/*
 * Trampolines through which the kernel runs a task's signal and exception
 * handlers on the task's own stack (seed 7.6.1: "the operating system
 * constructs a simulated interrupt context on the stack and invokes the
 * handler"). The kernel builds a frame whose EIP is one of these, with the
 * handler in EBX and its argument in EAX; when the handler returns, a
 * software interrupt hands control back to the kernel, which resumes the
 * interrupted frame it kept.
 */
    .section .text
    .code32

    .globl signalTrampoline
signalTrampoline:               /* EAX = signal number, EBX = handler */
    pushl %eax
    call *%ebx
    addl $4, %esp
    int $0x31                   /* TaskManager::kSignalReturnVector */
1:  hlt                         /* Not reached: the kernel never returns here. */
    jmp 1b

    .globl exceptionTrampoline
exceptionTrampoline:            /* EAX = ExceptionInfo*, EBX = handler */
    pushl %eax
    call *%ebx                  /* Returns the ExceptionAction in AL. */
    addl $4, %esp
    int $0x32                   /* TaskManager::kExceptionReturnVector */
1:  hlt
    jmp 1b

    .globl resumeTrampoline
resumeTrampoline:               /* EBX = the handler's resumeIn function */
    call *%ebx
    call taskExitFromTrampoline
1:  hlt
    jmp 1b

    .section .note.GNU-stack, "", @progbits
