/*
 * Where the second processor starts (MP spec, appendix B.4): a STARTUP IPI
 * sends it to vector:0000 in real mode, so this code is copied to the page
 * AP_TRAMPOLINE_BASE below 1 MiB (SecondProcessor.cpp) and runs there. It
 * enters flat 32-bit protected mode with a GDT of its own, says it is alive,
 * and jumps to node 3's Multiboot entry with the Multiboot magic in EAX and
 * the information node 2 prepared in EBX, as a loader would. Node 3's
 * kernel then loads its own GDT and IDT like any other.
 *
 * The parameter block at the end is filled in by node 2 in the copy.
 */
#include <bsp/ApTrampoline.h>

    .section .rodata.ap_trampoline, "a"
    .code16
    .globl apTrampolineStart, apTrampolineEnd
apTrampolineStart:
    cli
    cld
    movw %cs, %ax
    movw %ax, %ds
    lgdtl gdtDescriptor - apTrampolineStart
    movl %cr0, %eax
    orl $1, %eax                                /* CR0.PE */
    movl %eax, %cr0
    ljmpl $0x08, $(AP_TRAMPOLINE_BASE + protectedMode - apTrampolineStart)

    .code32
protectedMode:
    movw $0x10, %ax
    movw %ax, %ds
    movw %ax, %es
    movw %ax, %ss
    movw %ax, %fs
    movw %ax, %gs
    movl $(AP_TRAMPOLINE_BASE + AP_TRAMPOLINE_ALIVE), %ebx
    movl $AP_TRAMPOLINE_ALIVE_MAGIC, (%ebx)     /* Node 2 waits for this word. */
    movl $(AP_TRAMPOLINE_BASE + AP_TRAMPOLINE_ENTRY), %ebx
    movl (%ebx), %ecx                           /* Node 3's entry point */
    movl $(AP_TRAMPOLINE_BASE + AP_TRAMPOLINE_INFO), %ebx
    movl (%ebx), %ebx                           /* its Multiboot information */
    movl $0x2BADB002, %eax
    jmp *%ecx

    .align 8
gdt:
    .quad 0                                     /* null */
    .quad 0x00CF9A000000FFFF                    /* 0x08: flat 32-bit code, ring 0 */
    .quad 0x00CF92000000FFFF                    /* 0x10: flat data, ring 0 */
gdtDescriptor:
    .word gdtDescriptor - gdt - 1
    .long AP_TRAMPOLINE_BASE + gdt - apTrampolineStart

    .org AP_TRAMPOLINE_ALIVE
    .long 0
    .org AP_TRAMPOLINE_ENTRY
    .long 0
    .org AP_TRAMPOLINE_INFO
    .long 0
apTrampolineEnd:

    .section .note.GNU-stack, "", @progbits
