// The data model of an application's Modbus register map.
#include <mbline/ApplicationMapModel.hpp>

namespace mbline {

using dcos::app::ModbusMapEntry;
using dcos::app::ModbusSource;
using dcos::app::ModbusTable;
using modbus::ExceptionCode;

const ModbusMapEntry* ApplicationMapModel::find(ModbusTable table, uint32_t address) const
{
    // Linear: a map holds at most kMaximumModbusMapEntries entries, and the
    // slave serves one request at a time in the line's task.
    for (const ModbusMapEntry& entry : map_) {
        if (entry.table == table && address >= entry.address && address - entry.address < entry.count) {
            return &entry;
        }
    }
    return nullptr;
}

bool ApplicationMapModel::covered(ModbusTable table, uint16_t address, uint16_t quantity) const
{
    // Entry by entry: each found entry covers the range up to its end.
    uint32_t next = address;
    const uint32_t end = uint32_t{address} + quantity;
    while (next < end) {
        const ModbusMapEntry* entry = find(table, next);
        if (entry == nullptr) {
            return false;
        }
        next = entry->address + entry->count;
    }
    return true;
}

template <class Each>
ExceptionCode ApplicationMapModel::forEachEntry(ModbusTable table, uint16_t address, uint16_t quantity, Each each)
{
    if (!covered(table, address, quantity)) {
        return ExceptionCode::IllegalDataAddress;
    }
    uint32_t done = 0;
    while (done < quantity) {
        const uint32_t at = uint32_t{address} + done;
        const ModbusMapEntry& entry = *find(table, at);
        const uint32_t first = at - entry.address;
        const uint32_t chunk = entry.count - first < quantity - done ? entry.count - first : quantity - done;
        if (const ExceptionCode code = each(entry, first, done, chunk); code != ExceptionCode::None) {
            return code;
        }
        done += chunk;
    }
    return ExceptionCode::None;
}

ExceptionCode ApplicationMapModel::readBits(ModbusTable table, uint16_t address, uint16_t quantity, uint8_t* bits)
{
    return forEachEntry(table, address, quantity,
                        [&](const ModbusMapEntry& entry, uint32_t first, uint32_t done, uint32_t chunk) {
        if (entry.source == ModbusSource::Publisher) {
            dcos::DsmPage page{};
            if (const ExceptionCode code = backend_.readPage(entry.object, page); code != ExceptionCode::None) {
                return code;
            }
            for (uint32_t i = 0; i < chunk; ++i) {
                modbus::setBit(bits, done + i, modbus::getBit(page.bytes + entry.offset, first + i));
            }
        } else {
            // The configuration rules put only digital outputs in bit tables.
            uint16_t outputs = 0;
            if (const ExceptionCode code = backend_.readDigitalOutputs(outputs); code != ExceptionCode::None) {
                return code;
            }
            for (uint32_t i = 0; i < chunk; ++i) {
                modbus::setBit(bits, done + i, ((outputs >> (entry.offset + first + i)) & 1) != 0);
            }
        }
        return ExceptionCode::None;
    });
}

ExceptionCode ApplicationMapModel::readRegisters(ModbusTable table, uint16_t address, uint16_t quantity,
                                                 uint16_t* values)
{
    return forEachEntry(table, address, quantity,
                        [&](const ModbusMapEntry& entry, uint32_t first, uint32_t done, uint32_t chunk) {
        if (entry.source == ModbusSource::Publisher) {
            dcos::DsmPage page{};
            if (const ExceptionCode code = backend_.readPage(entry.object, page); code != ExceptionCode::None) {
                return code;
            }
            for (uint32_t i = 0; i < chunk; ++i) {
                const uint8_t* bytes = page.bytes + entry.offset + 2 * (first + i);
                values[done + i] = static_cast<uint16_t>((bytes[0] << 8) | bytes[1]);
            }
        } else {
            // The configuration rules put only analog inputs in register tables.
            for (uint32_t i = 0; i < chunk; ++i) {
                const ExceptionCode code = backend_.readAnalogInput(entry.offset + first + i, values[done + i]);
                if (code != ExceptionCode::None) {
                    return code;
                }
            }
        }
        return ExceptionCode::None;
    });
}

ExceptionCode ApplicationMapModel::readCoils(uint16_t address, uint16_t quantity, uint8_t* bits)
{
    return readBits(ModbusTable::Coils, address, quantity, bits);
}

ExceptionCode ApplicationMapModel::readDiscreteInputs(uint16_t address, uint16_t quantity, uint8_t* bits)
{
    return readBits(ModbusTable::DiscreteInputs, address, quantity, bits);
}

ExceptionCode ApplicationMapModel::readHoldingRegisters(uint16_t address, uint16_t quantity, uint16_t* values)
{
    return readRegisters(ModbusTable::HoldingRegisters, address, quantity, values);
}

ExceptionCode ApplicationMapModel::readInputRegisters(uint16_t address, uint16_t quantity, uint16_t* values)
{
    return readRegisters(ModbusTable::InputRegisters, address, quantity, values);
}

ExceptionCode ApplicationMapModel::writeCoils(uint16_t address, uint16_t quantity, const uint8_t* bits)
{
    return forEachEntry(ModbusTable::Coils, address, quantity,
                        [&](const ModbusMapEntry& entry, uint32_t first, uint32_t done, uint32_t chunk) {
        if (entry.source == ModbusSource::Publisher) {
            dcos::DsmPage page{};
            if (const ExceptionCode code = backend_.readPage(entry.object, page); code != ExceptionCode::None) {
                return code;
            }
            for (uint32_t i = 0; i < chunk; ++i) {
                modbus::setBit(page.bytes + entry.offset, first + i, modbus::getBit(bits, done + i));
            }
            if (const ExceptionCode code = backend_.writePage(entry.object, page); code != ExceptionCode::None) {
                return code;
            }
        } else {
            uint16_t mask = 0;
            uint16_t outputs = 0;
            for (uint32_t i = 0; i < chunk; ++i) {
                const uint16_t bit = static_cast<uint16_t>(1u << (entry.offset + first + i));
                mask = static_cast<uint16_t>(mask | bit);
                if (modbus::getBit(bits, done + i)) {
                    outputs = static_cast<uint16_t>(outputs | bit);
                }
            }
            if (const ExceptionCode code = backend_.writeDigitalOutputs(mask, outputs); code != ExceptionCode::None) {
                return code;
            }
        }
        return ExceptionCode::None;
    });
}

ExceptionCode ApplicationMapModel::writeHoldingRegisters(uint16_t address, uint16_t quantity, const uint16_t* values)
{
    return forEachEntry(ModbusTable::HoldingRegisters, address, quantity,
                        [&](const ModbusMapEntry& entry, uint32_t first, uint32_t done, uint32_t chunk) {
        // The configuration rules allow only writable publishers here.
        dcos::DsmPage page{};
        if (const ExceptionCode code = backend_.readPage(entry.object, page); code != ExceptionCode::None) {
            return code;
        }
        for (uint32_t i = 0; i < chunk; ++i) {
            uint8_t* bytes = page.bytes + entry.offset + 2 * (first + i);
            bytes[0] = static_cast<uint8_t>(values[done + i] >> 8);
            bytes[1] = static_cast<uint8_t>(values[done + i]);
        }
        if (const ExceptionCode code = backend_.writePage(entry.object, page); code != ExceptionCode::None) {
            return code;
        }
        return ExceptionCode::None;
    });
}

} // namespace mbline
