#include <iobus/IsaResourceManager.hpp>

#include <arch_x86/Cpu.hpp>
#include <runtime/Format.hpp>

namespace iobus {

namespace {

constexpr size_t kNameCapacity = sizeof(IsaReservation::claimant);

// The length of a claimant's name, or kNameCapacity when it is too long.
size_t nameLength(const char* name)
{
    size_t length = 0;
    while (length < kNameCapacity && name[length] != '\0') {
        ++length;
    }
    return length;
}

bool sameName(const char* a, const char* b)
{
    for (size_t i = 0; i < kNameCapacity; ++i) {
        if (a[i] != b[i]) {
            return false;
        }
        if (a[i] == '\0') {
            return true;
        }
    }
    return true;
}

void copyName(char (&to)[16], const char* from)
{
    size_t i = 0;
    for (; i + 1 < kNameCapacity && from[i] != '\0'; ++i) {
        to[i] = from[i];
    }
    to[i] = '\0';
}

// The devices soldered onto the 486 board (bsp_486) and the emulator's exit
// port. The slave 8259A is cascaded on line 2.
struct FixedDevice {
    const char* name;
    uint16_t first;
    uint16_t size;
    uint8_t line;
};

constexpr FixedDevice kBoardDevices[] = {
    {"pic-master", 0x20, 2, 2},
    {"pit", 0x40, 4, 0},
    {"cmos-rtc", 0x70, 2, 8},
    {"pic-slave", 0xA0, 2, kNoIrq},
    {"debug-exit", 0xF4, 4, kNoIrq},
    {"com1", 0x3F8, 8, 4},
};

IsaResourceManager boardManager;

} // namespace

dcos::Status IsaResourceManager::reserve(const char* claimant, uint16_t first, uint16_t size, uint8_t line,
                                         IsaConflict* conflict)
{
    if (size == 0 || uint32_t{first} + size - 1u > 0xFFFFu) {
        return dcos::Status::InvalidArgument;
    }
    return add(claimant, true, PortRange{first, static_cast<uint16_t>(first + size - 1u)}, line, conflict);
}

dcos::Status IsaResourceManager::reserveLine(const char* claimant, uint8_t line, IsaConflict* conflict)
{
    if (line == kNoIrq) {
        return dcos::Status::InvalidArgument;
    }
    return add(claimant, false, PortRange{0, 0}, line, conflict);
}

dcos::Status IsaResourceManager::add(const char* claimant, bool hasPorts, PortRange ports, uint8_t line,
                                     IsaConflict* conflict)
{
    if (claimant == nullptr || claimant[0] == '\0' || nameLength(claimant) >= kNameCapacity) {
        return dcos::Status::InvalidArgument;
    }
    if (line != kNoIrq && line >= kLineCount) {
        return dcos::Status::InvalidArgument;
    }
    arch_x86::InterruptGuard guard;
    for (size_t i = 0; i < count_; ++i) {
        const IsaReservation& held = entries_[i];
        const bool portClash = hasPorts && held.hasPorts && held.ports.overlaps(ports);
        const bool lineClash = line != kNoIrq && held.line == line;
        if (!portClash && !lineClash) {
            continue;
        }
        if (conflict != nullptr) {
            *conflict = IsaConflict{};
            conflict->irq = !portClash;
            copyName(conflict->wantedBy, claimant);
            conflict->wanted = ports;
            conflict->wantedLine = line;
            copyName(conflict->heldBy, held.claimant);
            conflict->held = held.ports;
            conflict->heldLine = held.line;
        }
        return dcos::Status::AlreadyExists;
    }
    if (count_ == kCapacity) {
        return dcos::Status::TableFull;
    }
    IsaReservation& entry = entries_[count_];
    copyName(entry.claimant, claimant);
    entry.hasPorts = hasPorts;
    entry.ports = ports;
    entry.line = line;
    ++count_;
    return dcos::Status::Ok;
}

size_t IsaResourceManager::release(const char* claimant)
{
    if (claimant == nullptr) {
        return 0;
    }
    arch_x86::InterruptGuard guard;
    size_t released = 0;
    size_t kept = 0;
    for (size_t i = 0; i < count_; ++i) {
        if (sameName(entries_[i].claimant, claimant)) {
            ++released;
        } else {
            entries_[kept++] = entries_[i];
        }
    }
    count_ = kept;
    return released;
}

bool IsaResourceManager::entry(size_t index, IsaReservation& out) const
{
    arch_x86::InterruptGuard guard;
    if (index >= count_) {
        return false;
    }
    out = entries_[index];
    return true;
}

size_t IsaResourceManager::describe(const IsaConflict& conflict, char* buffer, size_t capacity)
{
    if (conflict.irq) {
        return runtime::formatToBuffer(buffer, capacity, "IRQ %u wanted by %s is held by %s",
                                       static_cast<unsigned>(conflict.wantedLine), conflict.wantedBy,
                                       conflict.heldBy);
    }
    return runtime::formatToBuffer(buffer, capacity, "ports 0x%03x-0x%03x wanted by %s are held by %s (0x%03x-0x%03x)",
                                   conflict.wanted.first, conflict.wanted.last, conflict.wantedBy, conflict.heldBy,
                                   conflict.held.first, conflict.held.last);
}

void IsaResourceManager::registerBoardDevices()
{
    {
        arch_x86::InterruptGuard guard;
        if (boardDevicesRegistered_) {
            return;
        }
        boardDevicesRegistered_ = true;
    }
    for (const FixedDevice& device : kBoardDevices) {
        (void)reserve(device.name, device.first, device.size, device.line, nullptr);
    }
}

IsaResourceManager& isaResources()
{
    boardManager.registerBoardDevices();
    return boardManager;
}

} // namespace iobus
