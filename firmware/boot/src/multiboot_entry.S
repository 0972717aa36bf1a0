/*
 * Multiboot v1 entry point (Multiboot Specification 0.6.96).
 *
 * QEMU's -kernel and GRUB load the ELF image, leave the CPU in flat 32-bit
 * protected mode with paging and interrupts off, EAX = 0x2BADB002 and EBX
 * pointing at the Multiboot information structure (spec 3.2). This stub
 * gives the kernel a stack, clears .bss, and hands both registers to
 * bootFromMultiboot(), which turns them into the loader-neutral BootInfo.
 * Nothing after that point knows which loader started the node.
 */
    .set MULTIBOOT_MAGIC,         0x1BADB002   /* spec 3.1.1 */
    .set MULTIBOOT_PAGE_ALIGN,    1 << 0       /* modules on 4 KiB boundaries */
    .set MULTIBOOT_MEMORY_INFO,   1 << 1       /* ask for mem_lower/mem_upper */
    .set MULTIBOOT_FLAGS,         MULTIBOOT_PAGE_ALIGN | MULTIBOOT_MEMORY_INFO
    .set MULTIBOOT_CHECKSUM,      -(MULTIBOOT_MAGIC + MULTIBOOT_FLAGS)

    .section .multiboot, "a"
    .align 4
    .long MULTIBOOT_MAGIC
    .long MULTIBOOT_FLAGS
    .long MULTIBOOT_CHECKSUM

    .section .bss
    .align 16
    .globl bootStackBottom, bootStackTop
bootStackBottom:
    .skip 16384
bootStackTop:

    .section .text
    .code32
    .globl _start
_start:
    cli
    cld
    movl $bootStackTop, %esp
    movl %eax, %esi             /* Keep the loader's magic out of the way of
                                   the .bss clear; EBX is not touched by it. */

    /* Clear .bss, except the stack we are standing on, which is also .bss
     * but needs no zeroing. */
    movl $__bss_start, %edi
    movl $bootStackBottom, %ecx
    subl %edi, %ecx
    xorl %eax, %eax
    rep stosb
    movl $bootStackTop, %edi
    movl $__bss_end, %ecx
    subl %edi, %ecx
    rep stosb

    xorl %ebp, %ebp             /* Every register starts defined, EBP too. */
    pushl %ebx                  /* Multiboot information structure */
    pushl %esi                  /* Multiboot magic */
    call bootFromMultiboot
1:  cli
    hlt
    jmp 1b

/* The firmware has no executable stack; say so to the linker. */
    .section .note.GNU-stack, "", @progbits
