#include <can/LinkError.hpp>

namespace can {

const char* linkErrorName(LinkError error)
{
    switch (error) {
    case LinkError::Ok: return "ok";
    case LinkError::InvalidIdentifier: return "identifier out of range";
    case LinkError::InvalidDataLength: return "data length above 8";
    case LinkError::NotExtendedFrame: return "not an extended frame";
    case LinkError::UnexpectedRemoteFrame: return "unexpected remote frame";
    case LinkError::InvalidPriority: return "priority out of range";
    case LinkError::InvalidNodeNumber: return "invalid node number";
    case LinkError::UnassignedMessageType: return "unassigned message type";
    case LinkError::TimeoutA: return "N_As time-out";
    case LinkError::TimeoutBs: return "N_Bs time-out";
    case LinkError::TimeoutCr: return "N_Cr time-out";
    case LinkError::WrongSequenceNumber: return "wrong sequence number";
    case LinkError::InvalidFlowStatus: return "invalid flow status";
    case LinkError::UnexpectedPdu: return "unexpected PDU";
    case LinkError::WaitLimitExceeded: return "too many wait frames";
    case LinkError::BufferOverflow: return "buffer overflow";
    case LinkError::ReservedPciType: return "reserved PCI type";
    case LinkError::InvalidSingleFrameLength: return "invalid single frame length";
    case LinkError::InvalidFirstFrame: return "invalid first frame";
    case LinkError::ShortFrame: return "frame too short";
    case LinkError::NotExpected: return "not expected";
    case LinkError::WrongIdentifier: return "wrong identifier";
    case LinkError::InvalidMessageLength: return "invalid message length";
    case LinkError::Busy: return "busy";
    case LinkError::InvalidConfiguration: return "invalid configuration";
    case LinkError::InvalidHexDigit: return "invalid hex digit";
    case LinkError::LineTooLong: return "line too long";
    case LinkError::InvalidLineLength: return "invalid line length";
    case LinkError::UnknownCommand: return "unknown command";
    case LinkError::InvalidArgument: return "invalid argument";
    case LinkError::LineInterrupted: return "line interrupted";
    case LinkError::BufferTooSmall: return "buffer too small";
    }
    return "unknown link error";
}

dcos::Status toStatus(LinkError error)
{
    switch (error) {
    case LinkError::Ok:
        return dcos::Status::Ok;
    case LinkError::TimeoutA:
    case LinkError::TimeoutBs:
    case LinkError::TimeoutCr:
        return dcos::Status::Timeout;
    case LinkError::BufferOverflow:
    case LinkError::BufferTooSmall:
        return dcos::Status::NoMemory;
    case LinkError::Busy:
        return dcos::Status::Busy;
    case LinkError::UnknownCommand:
        return dcos::Status::NotSupported;
    case LinkError::InvalidIdentifier:
    case LinkError::InvalidDataLength:
    case LinkError::NotExtendedFrame:
    case LinkError::UnexpectedRemoteFrame:
    case LinkError::InvalidPriority:
    case LinkError::InvalidNodeNumber:
    case LinkError::UnassignedMessageType:
    case LinkError::WrongSequenceNumber:
    case LinkError::InvalidFlowStatus:
    case LinkError::UnexpectedPdu:
    case LinkError::WaitLimitExceeded:
    case LinkError::ReservedPciType:
    case LinkError::InvalidSingleFrameLength:
    case LinkError::InvalidFirstFrame:
    case LinkError::ShortFrame:
    case LinkError::NotExpected:
    case LinkError::WrongIdentifier:
    case LinkError::InvalidMessageLength:
    case LinkError::InvalidConfiguration:
    case LinkError::InvalidHexDigit:
    case LinkError::LineTooLong:
    case LinkError::InvalidLineLength:
    case LinkError::InvalidArgument:
    case LinkError::LineInterrupted:
        return dcos::Status::InvalidArgument;
    }
    return dcos::Status::InvalidArgument;
}

} // namespace can
