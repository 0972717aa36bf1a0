/*
 * The card's boot sector (docs/boot.md, "How a controller starts"). The
 * BIOS loads it at 0x7C00 and runs it in real mode with DL the drive it
 * came from. It loads the stage loader (sectors 1 to 255 of the card,
 * boot/CardLayout.hpp) at 0x10000 with the BIOS's extended disk read
 * (INT 13h AH=42h, EDD 3.0), enables the A20 gate, switches to flat 32-bit
 * protected mode and jumps to the stage loader with interrupts off.
 * Failures are written to COM1 (the console; nothing is on the screen of
 * a controller) and the processor halts.
 */
    .set STAGE_LBA,      1
    .set STAGE_SECTORS,  255
    .set STAGE_SEGMENT,  0x1000        /* 0x10000 */
    .set STAGE_ADDRESS,  0x10000
    .set CHUNK_SECTORS,  64            /* 32 KiB a read: every BIOS takes that much */
    .set STACK_TOP,      0x90000       /* below the extended BIOS data area */
    .set COM1,           0x3F8
    .set COM1_LSR,       0x3FD
    .set LSR_THRE,       0x20

    .code16
    .section .text
    .globl _start
_start:
    cli
    xorw %ax, %ax
    movw %ax, %ds
    movw %ax, %es
    movw %ax, %ss
    movw $0x7C00, %sp
    ljmp $0, $normalised          /* some BIOSes enter at 07C0:0000 */
normalised:
    sti
    movb %dl, boot_drive

    /* A20 through the BIOS (INT 15h AX=2401h); the stage loader checks it
     * and tries the other ways if this one did not work. */
    movw $0x2401, %ax
    int $0x15

    /* The extended read is required: the card's stage loader lies beyond
     * what CHS addressing of some BIOSes reaches, and every BIOS since the
     * late 1990s has it (INT 13h AH=41h, EDD 3.0, 7.3). */
    movb $0x41, %ah
    movw $0x55AA, %bx
    movb boot_drive, %dl
    int $0x13
    jc no_extensions
    cmpw $0xAA55, %bx
    jne no_extensions
    testb $1, %cl                 /* fixed disk access subset (AH=42h) */
    jz no_extensions

    movw $STAGE_SECTORS, remaining
read_chunk:
    movw remaining, %cx
    cmpw $CHUNK_SECTORS, %cx
    jbe 1f
    movw $CHUNK_SECTORS, %cx
1:  movw %cx, dap_count
    movw $dap, %si
    movb $0x42, %ah
    movb boot_drive, %dl
    int $0x13
    jc read_error
    movw dap_count, %cx           /* the BIOS reports what it read here */
    testw %cx, %cx
    jz read_error
    movw %cx, %ax
    shlw $5, %ax                  /* 512 bytes = 32 paragraphs a sector */
    addw %ax, dap_segment
    addw %cx, dap_lba
    adcw $0, dap_lba + 2
    subw %cx, remaining
    ja read_chunk

    cli
    lgdt gdt_descriptor
    movl %cr0, %eax
    orl $1, %eax                  /* CR0.PE */
    movl %eax, %cr0
    ljmp $0x08, $protected

no_extensions:
    movw $no_extensions_text, %si
    jmp fail
read_error:
    movw $read_error_text, %si
fail:
    cld
1:  lodsb
    testb %al, %al
    jz halt
    movb %al, %bl
    movw $COM1_LSR, %dx
2:  inb %dx, %al
    testb $LSR_THRE, %al
    jz 2b
    movb %bl, %al
    movw $COM1, %dx
    outb %al, %dx
    jmp 1b
halt:
    cli
    hlt
    jmp halt

    .code32
protected:
    movw $0x10, %ax
    movw %ax, %ds
    movw %ax, %es
    movw %ax, %fs
    movw %ax, %gs
    movw %ax, %ss
    movl $STACK_TOP, %esp
    movzbl boot_drive, %eax
    movl $STAGE_ADDRESS, %ecx
    jmp *%ecx                      /* EAX: the BIOS's drive number */

    .code16
    .section .data
    .align 4
/* INT 13h AH=42h disk address packet (EDD 3.0, 7.3.2). */
dap:
    .byte 16, 0
dap_count:
    .word 0
dap_offset:
    .word 0
dap_segment:
    .word STAGE_SEGMENT
dap_lba:
    .long STAGE_LBA, 0
remaining:
    .word 0
boot_drive:
    .byte 0

/* Flat code and data segments, 4 GiB each, as the stage loader and the
 * kernel's Multiboot entry expect (the kernel installs its own GDT). */
    .align 8
gdt:
    .quad 0
    .quad 0x00CF9A000000FFFF        /* 0x08: code, base 0, limit 4 GiB, 32-bit */
    .quad 0x00CF92000000FFFF        /* 0x10: data, base 0, limit 4 GiB */
gdt_descriptor:
    .word gdt_descriptor - gdt - 1
    .long gdt

no_extensions_text:
    .asciz "DCOS boot: the BIOS has no extended disk read\r\n"
read_error_text:
    .asciz "DCOS boot: cannot read the stage loader from the card\r\n"

    .section .note.GNU-stack, "", @progbits
