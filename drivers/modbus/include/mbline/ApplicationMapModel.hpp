// The data model of an application's Modbus register map
// (dcos::app::ModbusMapEntry, docs/protocols/modbus.md).
//
// The map says which addresses of which table are bound to which bytes of a
// DSM publisher's page or to which I/O board points; this class turns a
// request for a range of addresses into reads and writes of those objects
// through a MapBackend, so that the translation (the entries a range
// crosses, registers high byte first in the page, bits packed from bit 0)
// is tested on the host with a fake backend and the controller's line
// supplies the real one.
//
// A request is served only when every address it names is mapped, which
// is checked before anything is read or written: a request naming an
// unmapped address changes nothing. A write to a page reads the page's
// latest contents, changes the bytes of each entry the request crosses and
// writes the page once per entry, so the bytes the request does not name
// keep their value. A backend failure in mid-request (ServerDeviceFailure)
// leaves the entries before it written, as a slave's device failure may.
#pragma once

#include <dcos/ApplicationDeclarations.hpp>
#include <dcos/DsmAgent.hpp>
#include <modbus/DataModel.hpp>

#include <stddef.h>
#include <stdint.h>

namespace mbline {

/// The objects a map's entries are bound to. Each call answers
/// ExceptionCode::None or the exception the slave sends back
/// (ServerDeviceFailure for an object that cannot be read or written).
class MapBackend {
public:
    /// The latest page of the publisher named @p publisher.
    virtual modbus::ExceptionCode readPage(const char* publisher, dcos::DsmPage& page) = 0;
    /// Publishes @p page on the publisher named @p publisher.
    virtual modbus::ExceptionCode writePage(const char* publisher, const dcos::DsmPage& page) = 0;
    /// The raw counts of analog input @p channel.
    virtual modbus::ExceptionCode readAnalogInput(uint32_t channel, uint16_t& counts) = 0;
    /// The digital outputs' word, bit n output n.
    virtual modbus::ExceptionCode readDigitalOutputs(uint16_t& outputs) = 0;
    /// Sets the outputs of @p mask to their bits in @p outputs, leaving the others.
    virtual modbus::ExceptionCode writeDigitalOutputs(uint16_t mask, uint16_t outputs) = 0;

protected:
    ~MapBackend() = default;
};

class ApplicationMapModel final : public modbus::DataModel {
public:
    /// Serves @p map, which the configuration rules have passed (no
    /// overlaps, every entry fits its source), through @p backend.
    ApplicationMapModel(const dcos::app::DeclarationList<dcos::app::ModbusMapEntry>& map, MapBackend& backend)
        : map_(map), backend_(backend)
    {
    }

    /// Serves @p map from now on (the same conditions as the constructor's).
    void serve(const dcos::app::DeclarationList<dcos::app::ModbusMapEntry>& map) { map_ = map; }

    modbus::ExceptionCode readCoils(uint16_t address, uint16_t quantity, uint8_t* bits) override;
    modbus::ExceptionCode readDiscreteInputs(uint16_t address, uint16_t quantity, uint8_t* bits) override;
    modbus::ExceptionCode readHoldingRegisters(uint16_t address, uint16_t quantity, uint16_t* values) override;
    modbus::ExceptionCode readInputRegisters(uint16_t address, uint16_t quantity, uint16_t* values) override;
    modbus::ExceptionCode writeCoils(uint16_t address, uint16_t quantity, const uint8_t* bits) override;
    modbus::ExceptionCode writeHoldingRegisters(uint16_t address, uint16_t quantity, const uint16_t* values) override;

private:
    /// The entry of @p table that holds @p address, or null.
    const dcos::app::ModbusMapEntry* find(dcos::app::ModbusTable table, uint32_t address) const;
    /// Whether every address of the range is in some entry of @p table.
    bool covered(dcos::app::ModbusTable table, uint16_t address, uint16_t quantity) const;
    /// Refuses a range with an unmapped address (IllegalDataAddress) before
    /// anything is read or written, then calls @p each(entry, first, done,
    /// chunk) for every entry the range crosses, in address order: the
    /// entry's item the chunk starts at, the request's items before it, and
    /// how many of the entry's items the request takes. Stops at the first
    /// exception @p each returns.
    template <class Each>
    modbus::ExceptionCode forEachEntry(dcos::app::ModbusTable table, uint16_t address, uint16_t quantity, Each each);
    modbus::ExceptionCode readBits(dcos::app::ModbusTable table, uint16_t address, uint16_t quantity, uint8_t* bits);
    modbus::ExceptionCode readRegisters(dcos::app::ModbusTable table, uint16_t address, uint16_t quantity,
                                        uint16_t* values);

    dcos::app::DeclarationList<dcos::app::ModbusMapEntry> map_;
    MapBackend& backend_;
};

} // namespace mbline
