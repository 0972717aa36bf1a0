#include <arch_x86/AssemblyLinkage.hpp>
#include <arch_x86/CpuException.hpp>
#include <arch_x86/FaultTasks.hpp>
#include <arch_x86/Gdt.hpp>
#include <arch_x86/Idt.hpp>
#include <arch_x86/Paging.hpp>

#include <stddef.h>

extern "C" {
void pageFaultTaskEntry();
void doubleFaultTaskEntry();
void faultRecoveryEntry();
[[noreturn]] void dcosPanicWithFrame(const arch_x86::InterruptFrame* frame, const char* reason);
}

namespace arch_x86 {

namespace {

// A 32-bit task state segment (Intel SDM Vol. 3, 7.2.1, Figure 7-2).
struct TaskStateSegment {
    uint16_t backLink, reserved0;
    uint32_t esp0;
    uint16_t ss0, reserved1;
    uint32_t esp1;
    uint16_t ss1, reserved2;
    uint32_t esp2;
    uint16_t ss2, reserved3;
    uint32_t cr3, eip, eflags, eax, ecx, edx, ebx, esp, ebp, esi, edi;
    uint16_t es, reserved4, cs, reserved5, ss, reserved6, ds, reserved7, fs, reserved8, gs, reserved9;
    uint16_t ldt, reserved10;
    uint16_t trap, ioMapBase;
};
static_assert(sizeof(TaskStateSegment) == 104, "the 32-bit TSS is 104 bytes");
static_assert(offsetof(TaskStateSegment, cr3) == 28 && offsetof(TaskStateSegment, es) == 72);

// EFLAGS bit 1 always reads as one; IF stays clear in the fault tasks.
constexpr uint32_t eflagsReserved = 1u << 1;
// A task gate (SDM Vol. 3, 6.11, Figure 6-2): present, DPL 0, type 0x5.
constexpr uint8_t gatePresentTask = 0x85;

alignas(16) TaskStateSegment mainTss;
alignas(16) TaskStateSegment pageFaultTss;
alignas(16) TaskStateSegment doubleFaultTss;
alignas(16) uint8_t pageFaultStack[FaultTasks::kStackBytes];
alignas(16) uint8_t doubleFaultStack[FaultTasks::kStackBytes];
alignas(16) uint8_t recoveryStack[FaultTasks::kStackBytes];

FaultRecord record;
InterruptFrame* recoveryFrame = nullptr;
// Set while a fault runs through the kernel on the recovery stack: a second
// fault then cannot be recovered from (its stack is the one in use).
volatile bool recovering = false;

uint32_t address(const void* pointer) { return static_cast<uint32_t>(reinterpret_cast<uintptr_t>(pointer)); }
uint32_t address(void (*function)()) { return static_cast<uint32_t>(reinterpret_cast<uintptr_t>(function)); }

void prepareFaultTask(TaskStateSegment& tss, void (*entry)(), uint8_t* stack)
{
    tss = {};
    tss.cr3 = Paging::directory();
    tss.eip = address(entry);
    tss.eflags = eflagsReserved;
    tss.esp = address(stack + FaultTasks::kStackBytes);
    tss.cs = Gdt::kernelCode;
    tss.ss = tss.ds = tss.es = tss.fs = tss.gs = Gdt::kernelData;
    tss.ioMapBase = sizeof(TaskStateSegment); // No I/O permission bitmap.
}

// The interrupted context as the entry stubs would have saved it.
void copyContext(const TaskStateSegment& from, InterruptFrame& to, uint32_t vector, uint32_t errorCode)
{
    to = {};
    to.gs = from.gs;
    to.fs = from.fs;
    to.es = from.es;
    to.ds = from.ds;
    to.edi = from.edi;
    to.esi = from.esi;
    to.ebp = from.ebp;
    to.espAtPushal = from.esp;
    to.ebx = from.ebx;
    to.edx = from.edx;
    to.ecx = from.ecx;
    to.eax = from.eax;
    to.vector = vector;
    to.errorCode = errorCode;
    to.eip = from.eip;
    to.cs = from.cs;
    to.eflags = from.eflags;
}

} // namespace

void FaultTasks::install()
{
    mainTss = {};
    mainTss.cr3 = Paging::directory();
    mainTss.ioMapBase = sizeof(TaskStateSegment);
    prepareFaultTask(pageFaultTss, pageFaultTaskEntry, pageFaultStack);
    prepareFaultTask(doubleFaultTss, doubleFaultTaskEntry, doubleFaultStack);
    const uint32_t limit = sizeof(TaskStateSegment) - 1;
    Gdt::setTaskStateSegment(Gdt::mainTss, address(&mainTss), limit);
    Gdt::setTaskStateSegment(Gdt::pageFaultTss, address(&pageFaultTss), limit);
    Gdt::setTaskStateSegment(Gdt::doubleFaultTss, address(&doubleFaultTss), limit);
    asm volatile("ltr %w0" : : "r"(Gdt::mainTss) : "memory");
    Idt::setGate(static_cast<unsigned>(CpuException::PageFault), Gdt::pageFaultTss, 0, gatePresentTask);
    Idt::setGate(static_cast<unsigned>(CpuException::DoubleFault), Gdt::doubleFaultTss, 0, gatePresentTask);
}

bool FaultTasks::isFaultFrame(const InterruptFrame* frame) { return frame != nullptr && frame == recoveryFrame; }

const FaultRecord& FaultTasks::lastFault() { return record; }

} // namespace arch_x86

using namespace arch_x86;

// Runs in a fault task with interrupts off. The back link names the task
// that faulted; for DCOS that is always the main TSS.
DCOS_ASM_LINKAGE void faultTaskMain(uint32_t vector, uint32_t errorCode)
{
    TaskStateSegment& self = vector == 8 ? doubleFaultTss : pageFaultTss;
    static InterruptFrame panicFrame;
    uint32_t cr2;
    asm volatile("movl %%cr2, %0" : "=r"(cr2));
    copyContext(mainTss, panicFrame, vector, errorCode);
    record = FaultRecord{vector, errorCode, cr2, mainTss.esp};
    if (self.backLink != Gdt::mainTss) {
        recoveryFrame = &panicFrame;
        dcosPanicWithFrame(&panicFrame, "fault inside a fault task");
    }
    if (vector == 8) {
        recoveryFrame = &panicFrame;
        dcosPanicWithFrame(&panicFrame, "double fault: the processor could not deliver an exception");
    }
    if (recovering) {
        recoveryFrame = &panicFrame;
        dcosPanicWithFrame(&panicFrame, "page fault while the kernel handled a page fault");
    }
    // The frame sits at the top of the recovery stack; the kernel's handler
    // runs below it.
    auto* frame = reinterpret_cast<InterruptFrame*>(recoveryStack + FaultTasks::kStackBytes - sizeof(InterruptFrame));
    copyContext(mainTss, *frame, vector, errorCode);
    recoveryFrame = frame;
    recovering = true;
    mainTss.eip = address(faultRecoveryEntry);
    mainTss.esp = address(frame);
    mainTss.eflags = eflagsReserved; // Interrupts off until a task is resumed.
    mainTss.cs = Gdt::kernelCode;
    mainTss.ss = mainTss.ds = mainTss.es = mainTss.fs = mainTss.gs = Gdt::kernelData;
}

extern "C" void faultRecoveryFinished() { recovering = false; }
