// The application interface object of the system agent (dissertation 7.3).
//
// Applications call an agent through an interface object whose methods take
// logical ids, never pointers to kernel objects (seed 7.2.4), so that the
// same call can later trap into the kernel from ring 3 or travel to another
// node. This header covers device management (seed 7.3.2): a super-user task
// installs a driver with Create and removes it with Delete; any task then
// uses the device by id with Probe, Open, Close, Read, Write and Control.
//
//     // A super-user task at start-up:
//     static AnalogInputBoard board(window);
//     const Result<ObjectId> adc = systemAgent.Create(board, "adc0", Visibility::Regional);
//
//     // Any task:
//     const Result<ObjectId> adc = systemAgent.NameToObject("adc0");
//     systemAgent.Open(adc.value());
//     uint16_t sample;
//     systemAgent.Read(adc.value(), 3, &sample, sizeof sample);
//
// Errors common to every primitive that takes an id: InvalidId for the null
// id, a forged index or a free slot; WrongType for an id of another object
// type; StaleId for a device deleted since the id was issued; Remote for a
// device on another node (forwarded by the network manager once it exists).
//
// Context: Probe, Open, Close, Read, Write and Control may be called from an
// interrupt handler, because drivers never block (see dcos/Device.hpp). The
// privileged and configuration primitives (Create, Delete, AddObjects,
// NameToObject, XferOwnership) act on behalf of a task and refuse with
// InInterrupt when called from an interrupt handler.
//
// The agent serialises its own bookkeeping, but not the calls into a driver:
// two tasks (or a task and an interrupt handler) may be inside the same
// driver at once, and the driver protects its own state.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

class Device;

/// The system agent's device management services (seed 7.3.2).
///
/// The class has no state; use the object systemAgent. Real-time primitives
/// cost O(1); the configuration services NameToObject and AddObjects cost
/// O(N) in the number of device slots.
class SystemAgent {
public:
    /// Installs the driver object @p device and returns the id of the
    /// system device object that encapsulates it. Privileged. O(1).
    ///
    /// The calling task becomes the owner: when it ends, resource recovery
    /// closes and deletes the device, unless ownership was transferred
    /// before. @p name (at most 15 characters, or null or empty for an
    /// unnamed device) is the name NameToObject finds; the seed leaves its
    /// uniqueness to the user. @p device must outlive its installation.
    ///
    /// Fails with NotPermitted unless the caller is a super user,
    /// InInterrupt in an interrupt handler, AlreadyExists when @p device is
    /// already installed, InvalidArgument for a name that is too long or a
    /// bad visibility, and TableFull when every active slot is used (see
    /// AddObjects). The driver is not called; use Probe to check the hardware.
    static Result<ObjectId> Create(Device& device, const char* name, Visibility visibility);

    /// Removes the device @p device; every copy of its id turns stale. Privileged. O(1).
    ///
    /// Any super-user task may remove any device, since maintaining drivers
    /// is the super user's role (seed 7.3). The driver is not called. Fails
    /// with NotPermitted, InInterrupt, the id errors, and Busy while the
    /// device is open or a call into its driver is in progress.
    static Status Delete(ObjectId device);

    /// Asks the driver whether its hardware is present and usable. O(1) plus the driver.
    ///
    /// Allowed whether the device is open or not. Returns the driver's own
    /// status when the id is valid.
    static Status Probe(ObjectId device);

    /// Opens the device for transfers. O(1) plus the driver.
    ///
    /// Every Open is passed to the driver and, when it succeeds, counted;
    /// the device stays open until as many Close calls have succeeded. Opens
    /// are counted per device, not per task. Returns the driver's status, or
    /// Busy when 65535 opens are already counted.
    static Status Open(ObjectId device);

    /// Undoes one Open. O(1) plus the driver.
    ///
    /// Fails with NotOpen when no Open is counted (the driver is not
    /// called), or with the driver's status, in which case the open stays
    /// counted.
    static Status Close(ObjectId device);

    /// Reads up to @p length bytes from channel @p channel into @p buffer. O(1) plus the driver.
    ///
    /// The meaning of @p channel is the driver's (an input channel, a
    /// register bank, a byte offset). Returns the number of bytes read,
    /// which may be less than @p length, and 0 when no data is waiting.
    /// Fails with InvalidArgument for a null @p buffer with a non-zero
    /// @p length, NotOpen when the device is not open, the driver's status,
    /// and Corrupted when the driver reports more bytes than @p length (a
    /// driver bug that overran the buffer).
    static Result<size_t> Read(ObjectId device, uint32_t channel, void* buffer, size_t length);

    /// Writes up to @p length bytes from @p buffer to channel @p channel. O(1) plus the driver.
    ///
    /// Returns the number of bytes the device accepted. Fails like Read.
    static Result<size_t> Write(ObjectId device, uint32_t channel, const void* buffer, size_t length);

    /// Sends the device-specific command @p command. O(1) plus the driver.
    ///
    /// @p argument points to @p length bytes in the layout the driver
    /// documents for @p command; the driver may read and overwrite them. A
    /// command without data takes a null @p argument and length 0. Fails with
    /// InvalidArgument for a null @p argument with a non-zero @p length,
    /// NotOpen when the device is not open, and the driver's status
    /// (NotSupported for an unknown command).
    static Status Control(ObjectId device, uint32_t command, void* argument, size_t length);

    /// Configuration service: returns the id of the device named @p name on this node. O(N).
    ///
    /// Fails with NotFound, and InInterrupt in an interrupt handler.
    static Result<ObjectId> NameToObject(const char* name);

    /// Configuration service: activates @p count more device slots. Privileged. O(count).
    ///
    /// Eight slots are active from the start. @p count must be a non-zero
    /// multiple of eight (InvalidArgument), and the total may not exceed the
    /// capacity built into the kernel, 64 (TableFull); a refused request
    /// changes nothing. Also fails with NotPermitted and InInterrupt.
    static Status AddObjects(size_t count);

    /// Gives the device @p device to the task @p newOwner, or to the system
    /// when @p newOwner is the null id. O(1).
    ///
    /// Only the owner may transfer a device (NotOwner). A start-up task that
    /// installs drivers gives them to the system so that they survive its
    /// end. Fails with InvalidArgument when @p newOwner is neither a task id
    /// nor null, InInterrupt, and the id errors.
    static Status XferOwnership(ObjectId device, ObjectId newOwner);

    // Interrupt management (seed 7.3.3).

    /// An interrupt service routine: runs with interrupts enabled, so more
    /// urgent lines nest; it may post events, send signals and call the
    /// non-blocking device primitives, never a blocking service.
    using InterruptServiceRoutine = void (*)(void* context);

    /// Attaches isr(context) to a hardware interrupt line (privileged). A
    /// task the routine readies runs when the outermost interrupt returns.
    /// Busy when the line already has a routine. O(1).
    static Status InstallISR(unsigned line, InterruptServiceRoutine isr, void* context);
    /// Detaches the routine of a line installed with InstallISR (privileged). O(1).
    static Status RemoveISR(unsigned line);
    /// Holds off interrupts of this level and below while the calling task
    /// runs (level 0, the tick, cannot be held off; 0xFF holds off none).
    /// A level more urgent than the legal limit of the task's priority is
    /// lowered to that limit. Returns the level in force. O(1).
    static Result<uint8_t> SetInterruptLevel(uint8_t level);
    /// Sets the legal limit: the most urgent level a task of the given
    /// priority may set (privileged). O(1).
    static Status SetInterruptLevel(uint8_t priority, uint8_t legalLimit);
};

/// The object through which applications call the system agent.
inline constexpr SystemAgent systemAgent{};

} // namespace dcos
