#include <modbus/Slave.hpp>

namespace modbus {

ModbusResult<Slave> Slave::create(Transport& transport, Server& server, uint8_t address)
{
    if (address < kMinSlaveAddress || address > kMaxSlaveAddress) {
        return ModbusError::InvalidSlaveAddress;
    }
    Slave slave;
    slave.transport_ = &transport;
    slave.server_ = &server;
    slave.address_ = address;
    return slave;
}

StationStep Slave::onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs)
{
    if (transport_ == nullptr) {
        return {};
    }
    transport_->onBytes(bytes, count, nowNs);
    return serve();
}

StationStep Slave::poll(uint64_t nowNs)
{
    if (transport_ == nullptr) {
        return {};
    }
    transport_->poll(nowNs);
    return serve();
}

ModbusError Slave::onTransmitDone(uint64_t nowNs)
{
    if (!transmitting_) {
        return ModbusError::NotExpected;
    }
    transmitting_ = false;
    transport_->onTransmitDone(nowNs);
    return ModbusError::Ok;
}

StationStep Slave::serve()
{
    StationStep step;
    ReceivedFrame frame;
    while (transport_->takeFrame(frame)) {
        if (transmitting_) {
            ++counters_.droppedWhileSending;
            continue;
        }
        if (frame.unit != address_ && frame.unit != kBroadcastAddress) {
            ++counters_.otherAddresses;
            continue;
        }
        ++counters_.messages;
        if (frame.unit == kBroadcastAddress) {
            ++counters_.noResponses;
            if (Server::isBroadcastWrite(frame.pdu[0])) {
                // A broadcast's exception has nobody to go to ([SL] 2.1).
                (void)server_->handle(frame.pdu, frame.length, response_);
            }
            continue;
        }
        const ServerReply reply = server_->handle(frame.pdu, frame.length, response_);
        if (reply.exception != ExceptionCode::None) {
            ++counters_.exceptions;
        }
        const ModbusResult<size_t> adu = transport_->encode(address_, response_, reply.length, adu_, sizeof adu_);
        if (!adu.ok()) {
            // Only an empty reply gets here, and the transport delivers no
            // frame without a function code; nothing can be answered.
            ++counters_.noResponses;
            continue;
        }
        transmitting_ = true;
        step.transmit = adu_;
        step.transmitLength = adu.value();
    }
    return step;
}

} // namespace modbus
