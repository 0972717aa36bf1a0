#include <can/IsoTpConfig.hpp>

namespace can {

LinkError IsoTpConfig::validate() const
{
    if (txId > CanFrame::maxId(format) || rxId > CanFrame::maxId(format)) {
        return LinkError::InvalidIdentifier;
    }
    // With one identifier for both directions an end would take its own
    // flow control for the peer's, and the peer's data for its own echo.
    if (txId == rxId) {
        return LinkError::InvalidConfiguration;
    }
    if (!IsoTpPci::encodeSeparationTime(separationTimeNs).ok()) {
        return LinkError::InvalidConfiguration;
    }
    // A zero time-out would expire before any peer could answer.
    if (timeoutAsNs == 0 || timeoutBsNs == 0 || timeoutCrNs == 0) {
        return LinkError::InvalidConfiguration;
    }
    return LinkError::Ok;
}

} // namespace can
