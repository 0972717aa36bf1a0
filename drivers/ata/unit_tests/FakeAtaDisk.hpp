// A register-level stand-in for an ATA disk (a CompactFlash card in True
// IDE mode) on the primary channel, answering the recording port mock, for
// the host tests of AtaPioDisk. It follows ATA/ATAPI-6's PIO protocols as
// the driver depends on them: BSY while a command starts, DRQ per sector,
// ERR with the error register for a sector the test marks bad, and a
// command only after the device register selected the master.
#pragma once

#include <ata/AtaRegisters.hpp>

#include "../../../firmware/arch_x86/unit_tests/PortIoMock.hpp"

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace ata_test {

class FakeAtaDisk final {
public:
    explicit FakeAtaDisk(uint32_t sectors, std::string model = "DCOS FAKE CF");

    /// Sector contents (absent sectors read as zeros).
    std::vector<uint8_t> sector(uint32_t lba) const;
    void setSector(uint32_t lba, const std::vector<uint8_t>& bytes);

    // -- what the test plays --------------------------------------------------
    /// Reads and writes of this sector fail with ERR and this error register.
    void failSector(uint32_t lba, uint8_t error = 0x40) { failing_[lba] = error; }
    /// Writes to this sector fail with ERR (write fault); reads succeed.
    void failWritesTo(uint32_t lba, uint8_t error = 0x40) { failingWrites_[lba] = error; }
    /// The device never clears BSY again.
    void hang() { hung_ = true; }
    /// IDENTIFY reports no LBA support.
    void withoutLba() { lba_ = false; }

    // -- what the driver did --------------------------------------------------
    unsigned flushes = 0;
    unsigned commands = 0;
    uint8_t deviceControl = 0;

private:
    uint16_t readCommand(uint16_t offset, int width);
    void writeCommand(uint16_t offset, uint16_t value, int width);
    uint8_t status() const;
    void execute(uint8_t command);
    void nextSector();
    uint32_t address() const;

    struct CommandPorts final : port_io_mock::Responder {
        FakeAtaDisk* disk;
        uint32_t read(uint16_t offset, int width) override { return disk->readCommand(offset, width); }
        void write(uint16_t offset, uint32_t value, int width) override { disk->writeCommand(offset, static_cast<uint16_t>(value), width); }
    } commandPorts_;
    struct ControlPorts final : port_io_mock::Responder {
        FakeAtaDisk* disk;
        uint32_t read(uint16_t, int) override { return disk->status(); }
        void write(uint16_t, uint32_t value, int) override { disk->deviceControl = static_cast<uint8_t>(value); }
    } controlPorts_;

    uint32_t sectors_;
    std::string model_;
    bool lba_ = true;
    bool hung_ = false;
    std::map<uint32_t, std::vector<uint8_t>> data_;
    std::map<uint32_t, uint8_t> failing_;
    std::map<uint32_t, uint8_t> failingWrites_;

    uint8_t registers_[8] = {};
    uint8_t error_ = 0;
    bool errorBit_ = false;
    unsigned busyReads_ = 0; // BSY for this many more status reads
    // The transfer in progress.
    enum class Transfer { None, In, Out } transfer_ = Transfer::None;
    std::vector<uint8_t> buffer_;
    size_t position_ = 0;
    uint32_t transferLba_ = 0;
    uint32_t remaining_ = 0;
    bool identifying_ = false;
};

} // namespace ata_test
