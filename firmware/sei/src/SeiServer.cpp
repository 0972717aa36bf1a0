#include <sei/SeiServer.hpp>

namespace sei {

namespace {

// A text's length as a reply carries it: at most kSeiMaxText characters.
uint8_t textLength(const char* text)
{
    size_t length = 0;
    while (text != nullptr && length < kSeiMaxText && text[length] != '\0') {
        ++length;
    }
    return static_cast<uint8_t>(length);
}

} // namespace

size_t SeiServer::handle(const uint8_t* request, size_t length, uint8_t* reply, size_t capacity, uint64_t nowNs)
{
    SeiMessage answer;
    if (request == nullptr || length == 0 || !isSeiCommand(request[0])) {
        answer.kind = SeiMessageKind::Unreadable;
        answer.status = request == nullptr || length == 0 ? SeiStatus::Malformed : SeiStatus::UnknownCommand;
        return answer.encode(reply, capacity);
    }
    answer.kind = SeiMessageKind::Reply;
    answer.command = static_cast<SeiCommand>(request[0]);
    SeiMessage decoded;
    if (!SeiMessage::decode(request, length, decoded)) {
        answer.status = SeiStatus::Malformed;
        return answer.encode(reply, capacity);
    }
    const Outcome outcome = perform(decoded, request, length, nowNs, answer);
    if (!outcome.answer) {
        return 0;
    }
    answer.status = outcome.status;
    if (answer.status == SeiStatus::LockedOut) {
        answer.lockoutSecondsLeft = authenticator_.lockoutSecondsLeft(nowNs);
    }
    return answer.encode(reply, capacity);
}

SeiServer::Outcome SeiServer::perform(const SeiMessage& request, const uint8_t* bytes, size_t length, uint64_t nowNs,
                                      SeiMessage& reply)
{
    Outcome outcome;
    switch (request.command) {
    case SeiCommand::Identify:
        outcome.status = identify(nowNs, reply);
        break;
    case SeiCommand::Challenge:
        outcome.status = authenticator_.drawChallenge(nowNs, reply.challenge);
        break;
    case SeiCommand::GetConfiguration:
        outcome.status = getConfiguration(request, bytes, length, nowNs, reply);
        break;
    case SeiCommand::SetNodeId:
        outcome.status = authenticate(request, bytes, length, nowNs);
        if (outcome.status == SeiStatus::Ok) {
            outcome.status = setNodeId(request, reply);
        }
        break;
    case SeiCommand::SetBitRate:
        outcome.status = authenticate(request, bytes, length, nowNs);
        if (outcome.status == SeiStatus::Ok) {
            outcome.status = setBitRate(request, reply);
        }
        break;
    case SeiCommand::Restart:
        outcome.status = authenticate(request, bytes, length, nowNs);
        if (outcome.status == SeiStatus::Ok) {
            outcome.status = restart();
        }
        break;
    case SeiCommand::ProbeSerial:
        // Every matching node sends the same bytes, so any number of them
        // make one frame on the bus; the others stay silent.
        outcome.answer = probeMatches(backend_.identity().serial, request.probeBits, request.probeValue);
        break;
    case SeiCommand::Select:
        outcome = select(request, reply);
        break;
    case SeiCommand::Deselect:
        selected_ = false;
        outcome.answer = false;
        break;
    case SeiCommand::ActivateBitRate:
        // Every node on the bus takes it, so none answers (they would not
        // all say the same); the rate is the one an authenticated command
        // configured, so the command needs no MAC of its own.
        backend_.activateBitRate(request.delayMs, nowNs);
        outcome.answer = false;
        break;
    case SeiCommand::ListObjects:
    case SeiCommand::FindObject:
    case SeiCommand::ObjectInfo:
    case SeiCommand::NodeStatistics:
    case SeiCommand::Monitor:
        outcome.status = admitQuery(request, bytes, length, nowNs);
        if (outcome.status == SeiStatus::Ok) {
            outcome.status = manage(request, nowNs, reply);
        }
        break;
    case SeiCommand::SetConfiguration:
        outcome.status = authenticate(request, bytes, length, nowNs);
        if (outcome.status == SeiStatus::Ok) {
            outcome.status = setConfiguration(request, reply);
        }
        break;
    case SeiCommand::CreateTask:
    case SeiCommand::StartTask:
    case SeiCommand::StopTask:
    case SeiCommand::KillTask:
    case SeiCommand::CreateObject:
    case SeiCommand::DeleteObject:
    case SeiCommand::AddObjects:
        outcome.status = authenticate(request, bytes, length, nowNs);
        if (outcome.status == SeiStatus::Ok) {
            outcome.status = manage(request, nowNs, reply);
        }
        break;
    }
    return outcome;
}

SeiStatus SeiServer::admitQuery(const SeiMessage& request, const uint8_t* bytes, size_t length, uint64_t nowNs)
{
    // As GetConfiguration: a MAC that comes is checked; without one, the
    // query is open unless the node's queries are closed.
    if (request.hasMac) {
        return authenticate(request, bytes, length, nowNs);
    }
    if (backend_.queriesClosed()) {
        const SeiStatus admitted = authenticator_.admit(nowNs);
        return admitted != SeiStatus::Ok ? admitted : SeiStatus::NotPermitted;
    }
    return SeiStatus::Ok;
}

SeiStatus SeiServer::manage(const SeiMessage& request, uint64_t nowNs, SeiMessage& reply)
{
    uint8_t kernel = 0;
    switch (request.command) {
    case SeiCommand::ListObjects:
        kernel = backend_.listObjects(request.objectType, request.first, reply);
        break;
    case SeiCommand::FindObject:
        kernel = backend_.findObject(request.objectType, request.name, request.nameLength, reply.objectId);
        break;
    case SeiCommand::ObjectInfo:
        kernel = backend_.objectInfo(request.objectId, reply);
        break;
    case SeiCommand::NodeStatistics:
        kernel = backend_.nodeStatistics(reply);
        break;
    case SeiCommand::Monitor:
        kernel = backend_.monitor(request, nowNs);
        break;
    case SeiCommand::CreateTask:
        kernel = backend_.createTask(request, reply.objectId);
        break;
    case SeiCommand::StartTask:
        kernel = backend_.startTask(request.objectId);
        break;
    case SeiCommand::StopTask:
        kernel = backend_.stopTask(request.objectId);
        break;
    case SeiCommand::KillTask:
        kernel = backend_.killTask(request.objectId);
        break;
    case SeiCommand::CreateObject:
        kernel = backend_.createObject(request, reply.objectId);
        break;
    case SeiCommand::DeleteObject:
        kernel = backend_.deleteObject(request.objectId);
        break;
    case SeiCommand::AddObjects:
        kernel = backend_.addObjects(request.objectType, request.count);
        break;
    default:
        return SeiStatus::UnknownCommand;
    }
    reply.kernelStatus = kernel;
    return kernel == 0 ? SeiStatus::Ok : SeiStatus::KernelRefused;
}

SeiStatus SeiServer::setConfiguration(const SeiMessage& request, SeiMessage& reply)
{
    // The bit rate SetBitRate takes, for the same reasons; the node ids
    // SetNodeId takes, and 0, as GetConfiguration says it: none set, so the
    // kernel command line's or the default is used (a saved configuration
    // restored as it was).
    if (request.nodeId > kMaxNodeId || request.bitRate == 0 || !backend_.bitRateValid(request.bitRate)) {
        return SeiStatus::InvalidArgument;
    }
    SeiConfiguration configuration;
    configuration.nodeId = request.nodeId;
    configuration.bitRate = request.bitRate;
    configuration.queriesClosed = (request.flags & kSeiConfigurationQueriesClosed) != 0;
    configuration.lockoutSeconds = request.lockoutSeconds;
    configuration.commandLine = request.text;
    configuration.commandLineLength = request.textLength;
    const SeiResult<uint32_t> written = backend_.writeConfiguration(configuration);
    if (!written.ok()) {
        return written.status();
    }
    reply.sequence = written.value();
    return SeiStatus::Ok;
}

SeiStatus SeiServer::authenticate(const SeiMessage& request, const uint8_t* bytes, size_t length, uint64_t nowNs)
{
    // The MAC is the request's last bytes; it covers everything before it.
    return authenticator_.verify(bytes, length - kSeiMacSize, request.mac, nowNs);
}

SeiStatus SeiServer::identify(uint64_t nowNs, SeiMessage& reply)
{
    const SeiResult<SeiConfiguration> configuration = backend_.readConfiguration();
    if (!configuration.ok()) {
        return configuration.status();
    }
    const SeiIdentity identity = backend_.identity();
    reply.nodeId = identity.nodeId;
    reply.canNode = identity.canNode;
    reply.board = identity.board;
    reply.serial = identity.serial;
    reply.protocol = kSeiProtocolVersion;
    reply.flags = static_cast<uint8_t>((authenticator_.hasKey() ? kSeiIdentifyHasKey : 0) |
                                       (configuration.value().queriesClosed ? kSeiIdentifyQueriesClosed : 0) |
                                       (authenticator_.lockedOut(nowNs) ? kSeiIdentifyLockedOut : 0) |
                                       (selected_ ? kSeiIdentifySelected : 0));
    reply.bitRate = configuration.value().bitRate;
    reply.configuredNodeId = configuration.value().nodeId;
    reply.text = identity.versionText;
    reply.textLength = textLength(identity.versionText);
    return SeiStatus::Ok;
}

SeiStatus SeiServer::getConfiguration(const SeiMessage& request, const uint8_t* bytes, size_t length,
                                      uint64_t nowNs, SeiMessage& reply)
{
    // A MAC that comes is checked, whether or not the queries are closed:
    // a host that always sends one works with every node.
    if (request.hasMac) {
        const SeiStatus authenticated = authenticate(request, bytes, length, nowNs);
        if (authenticated != SeiStatus::Ok) {
            return authenticated;
        }
    }
    const SeiResult<SeiConfiguration> read = backend_.readConfiguration();
    if (!read.ok()) {
        return read.status();
    }
    const SeiConfiguration& configuration = read.value();
    if (configuration.queriesClosed && !request.hasMac) {
        // Without a key or while locked out, no MAC would help: say so first.
        const SeiStatus admitted = authenticator_.admit(nowNs);
        return admitted != SeiStatus::Ok ? admitted : SeiStatus::NotPermitted;
    }
    reply.sequence = configuration.sequence;
    reply.nodeId = configuration.nodeId;
    reply.bitRate = configuration.bitRate;
    reply.flags = configuration.queriesClosed ? kSeiConfigurationQueriesClosed : 0;
    reply.lockoutSeconds = configuration.lockoutSeconds;
    reply.text = configuration.commandLine;
    reply.textLength = textLength(configuration.commandLine);
    return SeiStatus::Ok;
}

SeiStatus SeiServer::setNodeId(const SeiMessage& request, SeiMessage& reply)
{
    if (request.nodeId < kMinNodeId || request.nodeId > kMaxNodeId) {
        return SeiStatus::InvalidArgument;
    }
    const SeiResult<uint32_t> written = backend_.writeNodeId(request.nodeId);
    if (!written.ok()) {
        return written.status();
    }
    reply.sequence = written.value();
    return SeiStatus::Ok;
}

SeiStatus SeiServer::setBitRate(const SeiMessage& request, SeiMessage& reply)
{
    // 0 would leave CAN down at the next start: the node could no longer be
    // reached over the bus to undo it. Only a rate the controller makes.
    if (request.bitRate == 0 || !backend_.bitRateValid(request.bitRate)) {
        return SeiStatus::InvalidArgument;
    }
    const SeiResult<uint32_t> written = backend_.writeBitRate(request.bitRate);
    if (!written.ok()) {
        return written.status();
    }
    reply.sequence = written.value();
    return SeiStatus::Ok;
}

SeiStatus SeiServer::restart()
{
    const SeiStatus prepared = backend_.prepareRestart();
    if (prepared == SeiStatus::Ok) {
        restartRequested_ = true;
    }
    return prepared;
}

SeiServer::Outcome SeiServer::select(const SeiMessage& request, SeiMessage& reply)
{
    // Only the node with that serial number is selected, and every other
    // that hears the Select is not, so at most one answers from 255.
    const SeiIdentity identity = backend_.identity();
    selected_ = identity.serial != 0 && request.serial == identity.serial;
    Outcome outcome;
    outcome.answer = selected_;
    reply.nodeId = identity.nodeId;
    reply.canNode = identity.canNode;
    return outcome;
}

} // namespace sei
