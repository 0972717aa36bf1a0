/*
 * The second processor's start-up code's place and parameter block, shared
 * by ApTrampoline.S and SecondProcessor.cpp (plain defines: the assembler
 * reads them too).
 */
#pragma once

/* The page the code is copied to: below 1 MiB and 4 KiB aligned, as a
 * STARTUP IPI's vector names a page (MP spec B.4.2); page 8 is free once
 * the BIOS has handed over. */
#define AP_TRAMPOLINE_BASE 0x8000
#define AP_TRAMPOLINE_PAGE (AP_TRAMPOLINE_BASE >> 12)
/* Offsets in the copy: the word the processor sets when it reaches
 * protected mode, node 3's entry point, and its Multiboot information. */
#define AP_TRAMPOLINE_ALIVE 0x100
#define AP_TRAMPOLINE_ENTRY 0x104
#define AP_TRAMPOLINE_INFO 0x108
#define AP_TRAMPOLINE_ALIVE_MAGIC 0x4E4F4433 /* "3DON" */
/* Node 3's Multiboot information and command line, after the code. */
#define AP_TRAMPOLINE_MULTIBOOT_INFO 0x200
#define AP_TRAMPOLINE_COMMAND_LINE 0x300
#define AP_TRAMPOLINE_COMMAND_LINE_BYTES 0x100
#define AP_TRAMPOLINE_LOADER_NAME 0x400
