/*
 * The local APIC's spurious-interrupt vector (Intel SDM Vol. 3A, 11.9): the
 * APIC raises it when an interrupt it was about to deliver went away. The
 * APIC set no in-service bit for it, so it takes no EOI, and nothing ran
 * on its behalf: it is counted and the interrupted code resumes at once,
 * without the kernel's interrupt entry.
 */
    .section .text.apic_spurious_entry, "ax", @progbits
    .code32
    .globl apicSpuriousEntry
    .type apicSpuriousEntry, @function
apicSpuriousEntry:
    incl apicSpuriousCount
    iret
    .size apicSpuriousEntry, . - apicSpuriousEntry

    .section .note.GNU-stack, "", @progbits
