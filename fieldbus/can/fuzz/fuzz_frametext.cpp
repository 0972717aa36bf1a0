// Fuzz target: the cansend/candump text form (can::FrameText), which takes
// what an engineer types at the controller's console and on a host's
// command line.
//
// The input is the text itself (NUL-terminated here). Whatever it holds,
// parsing either refuses it with a reason or yields a frame that formats
// and parses back to itself.
#include "FuzzCheck.hpp"

#include <can/FrameText.hpp>

#include <cstring>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const unsigned char* data, std::size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    const can::LinkResult<can::CanFrame> frame = can::FrameText::parse(text.c_str());
    if (!frame.ok()) {
        FUZZ_CHECK(frame.error() != can::LinkError::Ok);
        return 0;
    }
    const can::CanFrame& f = frame.value();
    FUZZ_CHECK(f.length() <= can::CanFrame::kMaxDataLength);
    FUZZ_CHECK(f.id() <= can::CanFrame::maxId(f.format()));
    char line[can::FrameText::kMaxFormattedLength + 1];
    const std::size_t n = can::FrameText::format(f, line, sizeof line);
    FUZZ_CHECK(n > 0 && n <= can::FrameText::kMaxFormattedLength && std::strlen(line) == n);
    // Back from candump's columns to cansend's form: identifier, '#', the bytes.
    std::string again(line, std::strcspn(line, " "));
    again += '#';
    if (f.isRemote()) {
        again += 'R';
        again += static_cast<char>('0' + f.length());
    } else {
        static const char digits[] = "0123456789ABCDEF";
        for (unsigned i = 0; i < f.length(); ++i) {
            again += digits[f.byte(i) >> 4];
            again += digits[f.byte(i) & 0xF];
        }
    }
    const can::LinkResult<can::CanFrame> reparsed = can::FrameText::parse(again.c_str());
    FUZZ_CHECK(reparsed.ok() && reparsed.value() == f);
    return 0;
}
