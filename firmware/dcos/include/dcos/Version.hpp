// The DCOS release and build identification.
#pragma once

namespace dcos {

/// The release this source tree is.
constexpr const char* versionString = "0.1.0";

/// The git revision the image was built from (set by the build).
const char* buildRevision();

} // namespace dcos
