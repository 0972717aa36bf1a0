#include <hostconfig/SerialSearch.hpp>

#include <sei/SeiMessage.hpp>

#include <utility>

namespace hostconfig {

namespace {

// What the search knows of a prefix (its top `bits` bits are `value`'s).
enum class Known : uint8_t {
    Unprobed, ///< Nothing yet: probe it before going down.
    Answered, ///< A node answered for it.
    Inferred, ///< Its parent holds a node and its 0 sibling was silent, so it should hold one; not probed.
};

struct Prefix {
    uint8_t bits;
    uint32_t value;
    Known known;
};

} // namespace

SerialSearch::SerialSearch(Probe probe, size_t maxSerials) : probe_(std::move(probe)), maxSerials_(maxSerials) {}

SerialSearch::Outcome SerialSearch::run()
{
    serials_.clear();
    probes_ = 0;
    // At most one open 1 branch per level waits on the stack, so it never
    // holds more than 33 prefixes.
    std::vector<Prefix> stack{{0, 0, Known::Unprobed}};
    const auto ask = [this](uint8_t bits, uint32_t value) {
        ++probes_;
        return probe_(bits, value);
    };
    while (!stack.empty()) {
        Prefix prefix = stack.back();
        stack.pop_back();
        // A whole serial number counts only once a node answered for it, so
        // an inferred one is probed: its node may have left meanwhile.
        const bool mustProbe =
            prefix.known == Known::Unprobed || (prefix.known == Known::Inferred && prefix.bits == sei::kSeiSerialBits);
        if (mustProbe) {
            const Answer answer = ask(prefix.bits, prefix.value);
            if (answer == Answer::Failed) {
                return Outcome::Failed;
            }
            if (answer == Answer::Silent) {
                continue;
            }
            prefix.known = Known::Answered;
        }
        if (prefix.bits == sei::kSeiSerialBits) {
            // Two nodes with the same serial number (a manufacturing
            // mistake) are one leaf: found once.
            serials_.push_back(prefix.value);
            if (serials_.size() > maxSerials_) {
                return Outcome::TooMany;
            }
            continue;
        }
        const uint8_t childBits = static_cast<uint8_t>(prefix.bits + 1);
        const uint32_t oneBit = uint32_t{1} << (sei::kSeiSerialBits - childBits);
        const Answer zero = ask(childBits, prefix.value);
        if (zero == Answer::Failed) {
            return Outcome::Failed;
        }
        // The 1 branch goes on the stack first, so the 0 branch is taken
        // first and the serial numbers come out in ascending order.
        if (zero == Answer::Match) {
            stack.push_back({childBits, prefix.value | oneBit, Known::Unprobed});
            stack.push_back({childBits, prefix.value, Known::Answered});
        } else {
            stack.push_back({childBits, prefix.value | oneBit, Known::Inferred});
        }
    }
    return Outcome::Done;
}

} // namespace hostconfig
