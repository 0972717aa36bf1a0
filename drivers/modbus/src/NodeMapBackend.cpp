// The node's objects behind an application's Modbus register map.
#include <mbline/NodeMapBackend.hpp>

#include <iobus/MfioClient.hpp>
#include <iobus/MfioRegisters.hpp>
#include <runtime/Text.hpp>

namespace mbline {

using dcos::Result;
using dcos::Status;
using dcos::dsmAgent;
using modbus::ExceptionCode;

void NodeMapBackend::useBoard(dcos::ObjectId board)
{
    board_ = board;
    failures_ = 0;
    lastFailure_ = Status::Ok;
}

void NodeMapBackend::closeSubscriptions()
{
    for (size_t i = 0; i < count_; ++i) {
        (void)dsmAgent.Close(publishers_[i].subscription);
    }
    count_ = 0;
}

ExceptionCode NodeMapBackend::fail(Status status)
{
    ++failures_;
    lastFailure_ = status;
    return ExceptionCode::ServerDeviceFailure;
}

NodeMapBackend::Publisher* NodeMapBackend::find(const char* name)
{
    for (size_t i = 0; i < count_; ++i) {
        if (publishers_[i].name == name || runtime::textEquals(publishers_[i].name, name)) {
            return &publishers_[i];
        }
    }
    // A map names at most kMaximumModbusMapEntries publishers, one per entry.
    if (count_ == dcos::app::kMaximumModbusMapEntries) {
        lastFailure_ = Status::TableFull;
        return nullptr;
    }
    const Result<dcos::ObjectId> publisher = dsmAgent.NameToObject(name);
    if (!publisher.ok()) {
        lastFailure_ = publisher.status();
        return nullptr;
    }
    const Result<dcos::ObjectId> subscription = dsmAgent.Open(publisher.value());
    if (!subscription.ok()) {
        lastFailure_ = subscription.status();
        return nullptr;
    }
    Publisher& made = publishers_[count_++];
    made = Publisher{};
    made.name = name;
    made.publisher = publisher.value();
    made.subscription = subscription.value();
    return &made;
}

ExceptionCode NodeMapBackend::readPage(const char* name, dcos::DsmPage& page)
{
    Publisher* publisher = find(name);
    if (publisher == nullptr) {
        return fail(lastFailure_);
    }
    dcos::DsmPage newer{};
    const Result<uint32_t> read = dsmAgent.Read(publisher->subscription, publisher->lastSeenDataId, newer, dcos::kPoll);
    if (read.ok()) {
        publisher->lastSeenDataId = read.value();
        publisher->page = newer;
    } else if (read.status() != Status::WouldBlock) {
        // WouldBlock only says nothing newer was written: the page seen last is the latest.
        return fail(read.status());
    }
    page = publisher->page;
    return ExceptionCode::None;
}

ExceptionCode NodeMapBackend::writePage(const char* name, const dcos::DsmPage& page)
{
    Publisher* publisher = find(name);
    if (publisher == nullptr) {
        return fail(lastFailure_);
    }
    const Result<uint32_t> written = dsmAgent.Write(publisher->publisher, page);
    return written.ok() ? ExceptionCode::None : fail(written.status());
}

ExceptionCode NodeMapBackend::readAnalogInput(uint32_t channel, uint16_t& counts)
{
    if (board_.isNull()) {
        return fail(Status::NotFound);
    }
    const Result<uint16_t> word = iobus::readAnalogInput(board_, channel);
    if (!word.ok()) {
        return fail(word.status());
    }
    counts = static_cast<uint16_t>(word.value() & iobus::mfio::kAdcDataCodeMask);
    return ExceptionCode::None;
}

ExceptionCode NodeMapBackend::readDigitalOutputs(uint16_t& outputs)
{
    if (board_.isNull()) {
        return fail(Status::NotFound);
    }
    const Result<uint16_t> word = iobus::readWord(board_, iobus::channel::kDigitalOutputs);
    if (!word.ok()) {
        return fail(word.status());
    }
    outputs = word.value();
    return ExceptionCode::None;
}

ExceptionCode NodeMapBackend::writeDigitalOutputs(uint16_t mask, uint16_t outputs)
{
    uint16_t current = 0;
    if (const ExceptionCode code = readDigitalOutputs(current); code != ExceptionCode::None) {
        return code;
    }
    const uint16_t word = static_cast<uint16_t>((current & ~mask) | (outputs & mask));
    const Status written = iobus::writeWord(board_, iobus::channel::kDigitalOutputs, word);
    return written == Status::Ok ? ExceptionCode::None : fail(written);
}

} // namespace mbline
