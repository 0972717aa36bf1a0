// How the console writes an object id: "0x" and eight hex digits, the same
// in every listing (tasks, semaphores, ports, pools, heaps, devices, app)
// and every report, so an id copied from one can be searched for in another.
#pragma once

#include <dcos/ObjectId.hpp>

namespace dcos::internal {

class IdText {
public:
    /// The null id, which names no object, is written "-".
    explicit IdText(ObjectId id)
    {
        if (id.isNull()) {
            text_[0] = '-';
            text_[1] = '\0';
            return;
        }
        static constexpr char digits[] = "0123456789abcdef";
        const uint32_t raw = id.raw();
        text_[0] = '0';
        text_[1] = 'x';
        for (unsigned i = 0; i < 8; ++i) {
            text_[2 + i] = digits[(raw >> (28 - 4 * i)) & 0xF];
        }
        text_[10] = '\0';
    }

    const char* c_str() const { return text_; }

private:
    char text_[11];
};

} // namespace dcos::internal
