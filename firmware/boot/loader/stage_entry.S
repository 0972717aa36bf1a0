/*
 * The stage loader's entry at 0x10000 (boot/CardLayout.hpp): the boot
 * sector jumps here in flat 32-bit protected mode, interrupts off, ESP at
 * 0x90000 and EAX the BIOS's boot drive. Clears .bss and calls stageMain.
 */
    .section .text.entry, "ax"
    .code32
    .globl _start
_start:
    cli
    cld
    movl %eax, %esi
    movl $__bss_start, %edi
    movl $__bss_end, %ecx
    subl %edi, %ecx
    xorl %eax, %eax
    rep stosb
    movl %esi, %eax               /* stageMain(bootDrive), regparm(3): in EAX */
    call stageMain
1:  cli
    hlt
    jmp 1b

    .section .note.GNU-stack, "", @progbits
