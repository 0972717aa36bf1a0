// What `dcos-mon --data` names: a field of a node's publication to follow,
// written PUB[@OFFSET][:FORMAT][=LABEL] (host_tools/mon/README.md). PUB is
// a publisher's name, which the tool looks up on the node (FindObject), or
// its id as 0x followed by hex digits; OFFSET the field's first byte in the
// publication's 16-byte page (default 0); FORMAT u8, i8, u16, i16, u32 or
// i32 (default i32); LABEL the name the field has in the output and the
// plot's legend (default the text before '='). Pure code, errors as values.
#pragma once

#include <sei/SeiMessage.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace hostmon {

struct ChannelSpec {
    /// The publisher's name, or empty when it was given by id.
    std::string publisherName;
    /// The publisher's id when given as 0x...; 0 until looked up otherwise.
    uint32_t publisherId = 0;
    uint8_t offset = 0;
    sei::SeiSampleFormat format = sei::SeiSampleFormat::I32;
    /// One word (no white space), so that an output line splits the same
    /// way whatever the label.
    std::string label;
};

/// Reads @p text; nothing, with @p why, when it is not such a field (an
/// empty or over-long name, a bad id, an offset past the page or a field
/// that does not fit it, an unknown format, a label with white space).
std::optional<ChannelSpec> parseChannelSpec(const std::string& text, std::string& why);

/// "u8", "i8", "u16", "i16", "u32", "i32".
const char* sampleFormatName(sei::SeiSampleFormat format);

} // namespace hostmon
