// The abstract device driver class of the system agent (dissertation 7.3.2).
//
// A device driver is a class that inherits from dcos::Device and overrides
// its member functions. A task with super-user privilege installs a driver
// object with systemAgent.Create, which returns the logical id of the system
// device object that encapsulates it; from then on every task reaches the
// driver only through the system agent's primitives Probe, Open, Close,
// Read, Write and Control, which take that id. The seed forbids direct calls
// on a device object, so the driver's functions are private virtual members
// here: only the system agent (a friend) can call them, and a driver keeps
// its overrides private as well.
//
// Contract for every driver function:
// - It completes in bounded time and never waits on a kernel object. The
//   agent lets tasks and interrupt handlers call it, so a driver whose
//   functions can run in both keeps its own state consistent (for example
//   with arch_x86::InterruptGuard around a register sequence). A task that
//   must wait for data waits on a semaphore or message port that the
//   driver's interrupt service routine signals (seed 7.3.3).
// - It reports errors as a Status and never panics on bad input from a task.
//
// The driver object must outlive its installation: it is normally a static
// object of the driver's module, and its destructor is protected and not
// virtual, because the kernel has no heap and never deletes a driver.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

namespace internal {
class DeviceManager;
} // namespace internal

/// Base class of every device driver object (seed 7.3.2).
///
/// Probe is the only function a driver must override; the others have
/// defaults that suit a driver without per-open state (Open and Close
/// succeed) or without the capability (Read, Write and Control report
/// NotSupported, so a digital output board need not implement Read).
class Device {
public:
    Device(const Device&) = delete;
    Device& operator=(const Device&) = delete;

    /// The id under which the system agent installed this driver, or the
    /// null id while it is not installed. A driver uses it in log messages.
    constexpr ObjectId id() const { return installedAs_; }

protected:
    /// Creates a driver object that is not yet installed.
    constexpr Device() = default;

    /// Not virtual, and protected so that no one deletes a driver through a
    /// Device pointer; see the header comment.
    ~Device() = default;

private:
    friend class internal::DeviceManager;

    /// Checks that the hardware is present and answers as expected.
    ///
    /// Called by the Probe primitive, at any time, whether the device is
    /// open or not. Returns Ok when the hardware is usable; any other status
    /// (typically NotFound for an empty slot, Corrupted for a board that
    /// answers wrongly) is returned to the caller unchanged.
    virtual Status Probe() = 0;

    /// Prepares the device for transfers.
    ///
    /// The agent calls it for every Open primitive and counts the opens that
    /// succeed; a driver that must initialise its hardware only once counts
    /// its own opens. A status other than Ok is returned to the caller and
    /// the open is not counted.
    virtual Status Open() { return Status::Ok; }

    /// Undoes one Open.
    ///
    /// The agent calls it for every Close primitive, only while at least one
    /// Open is counted, and when the task that installed the driver ends
    /// with the device still open (resource recovery), once per open. A
    /// status other than Ok is returned to the caller and the device stays
    /// open.
    virtual Status Close() { return Status::Ok; }

    /// Reads up to @p length bytes from @p channel into @p buffer.
    ///
    /// @p channel is what the driver defines it to be: an input channel of
    /// an I/O board, a register bank, or a byte offset in a memory-like
    /// device. The agent calls it only while the device is open, and
    /// guarantees that @p buffer is not null when @p length is not zero.
    /// Returns the number of bytes stored, at most @p length; 0 is a valid
    /// answer when no data is available, because a driver never waits.
    virtual Result<size_t> Read(uint32_t channel, void* buffer, size_t length)
    {
        (void)channel;
        (void)buffer;
        (void)length;
        return Status::NotSupported;
    }

    /// Writes up to @p length bytes from @p buffer to @p channel.
    ///
    /// @p channel has the same meaning as for Read. The agent calls it only
    /// while the device is open, and guarantees that @p buffer is not null
    /// when @p length is not zero. Returns the number of bytes accepted, at
    /// most @p length; fewer than @p length means the device's buffer is full.
    virtual Result<size_t> Write(uint32_t channel, const void* buffer, size_t length)
    {
        (void)channel;
        (void)buffer;
        (void)length;
        return Status::NotSupported;
    }

    /// Carries out the device-specific command @p command.
    ///
    /// @p argument points to @p length bytes that the command reads, writes
    /// or both, in a layout the driver documents for each command (for
    /// example a uint32_t baud rate, or a structure of gains it fills in).
    /// A command without data receives a null @p argument and length 0; the
    /// driver checks that @p length matches what the command needs and
    /// returns InvalidArgument otherwise, and NotSupported for a command code
    /// it does not know. The agent calls it only while the device is open,
    /// and guarantees that @p argument is not null when @p length is not zero.
    virtual Status Control(uint32_t command, void* argument, size_t length)
    {
        (void)command;
        (void)argument;
        (void)length;
        return Status::NotSupported;
    }

    // Set and cleared by the system agent; non-null while installed, which
    // stops the same driver object from being installed twice.
    ObjectId installedAs_{};
};

} // namespace dcos
