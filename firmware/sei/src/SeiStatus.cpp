#include <sei/SeiStatus.hpp>

namespace sei {

const char* seiStatusText(SeiStatus status)
{
    switch (status) {
    case SeiStatus::Ok: return "done";
    case SeiStatus::Malformed: return "a malformed request";
    case SeiStatus::UnknownCommand: return "no such command";
    case SeiStatus::NoChallenge: return "no challenge outstanding: ask for one first (each serves one attempt)";
    case SeiStatus::StaleChallenge: return "the challenge is older than 30 s: ask for a new one";
    case SeiStatus::BadMac: return "the MAC is wrong: wrong key, or an altered or replayed request";
    case SeiStatus::LockedOut: return "locked out after three wrong MACs";
    case SeiStatus::NoKey: return "the node holds no configuration key: nothing can be changed over the bus";
    case SeiStatus::InvalidArgument: return "a value the node cannot take";
    case SeiStatus::CardError: return "the node's card cannot be read or written; nothing changed";
    case SeiStatus::NotPermitted: return "the node's queries are closed: a MAC is needed";
    case SeiStatus::KernelRefused: return "the node's kernel refused it";
    }
    return "unknown status";
}

} // namespace sei
