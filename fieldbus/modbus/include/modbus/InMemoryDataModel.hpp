// A DataModel held in static arrays: the four tables of [AP] 4.3, each
// starting at address 0 with the size given as a template argument. Tests,
// examples and simple slaves use it directly; an application whose data lives
// elsewhere implements DataModel itself, with this class as the pattern.
//
// Any address past a table's size is IllegalDataAddress. A table of size 0
// answers every request for it with IllegalDataAddress. failNext() makes the
// next access answer ServerDeviceFailure, so that a test can reach the
// server's exception 04 path.
#pragma once

#include <modbus/DataModel.hpp>

namespace modbus {

template <size_t Coils, size_t DiscreteInputs, size_t HoldingRegisters, size_t InputRegisters>
class InMemoryDataModel final : public DataModel {
public:
    static_assert(Coils <= 0x10000 && DiscreteInputs <= 0x10000 && HoldingRegisters <= 0x10000
                      && InputRegisters <= 0x10000,
                  "a Modbus table has at most 65536 entries ([AP] 4.4)");

    ExceptionCode readCoils(uint16_t address, uint16_t quantity, uint8_t* bits) override
    {
        return readBits(coils_, Coils, address, quantity, bits);
    }
    ExceptionCode readDiscreteInputs(uint16_t address, uint16_t quantity, uint8_t* bits) override
    {
        return readBits(discreteInputs_, DiscreteInputs, address, quantity, bits);
    }
    ExceptionCode readHoldingRegisters(uint16_t address, uint16_t quantity, uint16_t* values) override
    {
        return readRegisters(holdingRegisters_, HoldingRegisters, address, quantity, values);
    }
    ExceptionCode readInputRegisters(uint16_t address, uint16_t quantity, uint16_t* values) override
    {
        return readRegisters(inputRegisters_, InputRegisters, address, quantity, values);
    }
    ExceptionCode writeCoils(uint16_t address, uint16_t quantity, const uint8_t* bits) override
    {
        const ExceptionCode checked = check(Coils, address, quantity);
        if (checked != ExceptionCode::None) {
            return checked;
        }
        for (size_t i = 0; i < quantity; ++i) {
            coils_[address + i] = getBit(bits, i);
        }
        return ExceptionCode::None;
    }
    ExceptionCode writeHoldingRegisters(uint16_t address, uint16_t quantity, const uint16_t* values) override
    {
        const ExceptionCode checked = check(HoldingRegisters, address, quantity);
        if (checked != ExceptionCode::None) {
            return checked;
        }
        for (size_t i = 0; i < quantity; ++i) {
            holdingRegisters_[address + i] = values[i];
        }
        return ExceptionCode::None;
    }

    /// Direct access for the application and the tests; the index is not checked.
    bool& coil(size_t index) { return coils_[index]; }
    bool& discreteInput(size_t index) { return discreteInputs_[index]; }
    uint16_t& holdingRegister(size_t index) { return holdingRegisters_[index]; }
    uint16_t& inputRegister(size_t index) { return inputRegisters_[index]; }

    /// Makes the next access answer ServerDeviceFailure, as a failing device would.
    void failNext() { failNext_ = true; }

private:
    // An array of size 0 is not C++, so an empty table keeps one unused entry.
    static constexpr size_t storage(size_t size) { return size == 0 ? 1 : size; }

    ExceptionCode check(size_t size, uint16_t address, uint16_t quantity)
    {
        if (failNext_) {
            failNext_ = false;
            return ExceptionCode::ServerDeviceFailure;
        }
        return static_cast<size_t>(address) + quantity <= size ? ExceptionCode::None
                                                               : ExceptionCode::IllegalDataAddress;
    }

    ExceptionCode readBits(const bool* table, size_t size, uint16_t address, uint16_t quantity, uint8_t* bits)
    {
        const ExceptionCode checked = check(size, address, quantity);
        if (checked != ExceptionCode::None) {
            return checked;
        }
        for (size_t i = 0; i < quantity; ++i) {
            setBit(bits, i, table[address + i]);
        }
        return ExceptionCode::None;
    }

    ExceptionCode readRegisters(const uint16_t* table, size_t size, uint16_t address, uint16_t quantity,
                                uint16_t* values)
    {
        const ExceptionCode checked = check(size, address, quantity);
        if (checked != ExceptionCode::None) {
            return checked;
        }
        for (size_t i = 0; i < quantity; ++i) {
            values[i] = table[address + i];
        }
        return ExceptionCode::None;
    }

    bool coils_[storage(Coils)] = {};
    bool discreteInputs_[storage(DiscreteInputs)] = {};
    uint16_t holdingRegisters_[storage(HoldingRegisters)] = {};
    uint16_t inputRegisters_[storage(InputRegisters)] = {};
    bool failNext_ = false;
};

} // namespace modbus
