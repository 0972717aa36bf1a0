// A network address of the network interfaces manager (seed 7.13, Fig. 7.14).
//
// The seed adapts Internet Protocol version 4's addresses: 32 bits, an 8-bit
// net id in the top octet, then a subnet id and a host id whose split is
// given by a subnet mask length (the number of leading bits that name the
// subnet, net id included). The first octet says what kind of address it is:
//
//     128 to 223         a node's protocol stack (unicast)
//     224 to 239         a multicast group
//     255.255.255.255    the limited broadcast (every node of the local subnet)
//     x.255.255.255      the directed broadcast of net x
//
// Other first octets are not used by DCOS and are refused where an address
// is configured. A network address names one protocol stack of one node; a
// node with several interfaces (multi-homed) has several, and the manager
// maps its 16-bit logical node id to all of them.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// A 32-bit network address, in host byte order. A value type: O(1) throughout.
class NetworkAddress {
public:
    /// What an address names, from its first octet (see above).
    enum class Kind : uint8_t {
        Invalid,           ///< A first octet DCOS does not use (0 to 127, 240 to 254).
        Unicast,           ///< One protocol stack of one node (128 to 223).
        Multicast,         ///< A group (224 to 239).
        LimitedBroadcast,  ///< 255.255.255.255.
        DirectedBroadcast, ///< x.255.255.255 for a unicast net x.
    };

    /// The longest subnet mask: a subnet of one address.
    static constexpr uint8_t kMaximumPrefixLength = 32;
    /// The shortest: the net id alone.
    static constexpr uint8_t kMinimumPrefixLength = 8;
    /// Characters of the longest text form, "255.255.255.255", and its terminator.
    static constexpr size_t kTextSize = 16;

    constexpr NetworkAddress() = default;
    constexpr explicit NetworkAddress(uint32_t raw) : raw_(raw) {}

    /// The address a.b.c.d.
    static constexpr NetworkAddress fromOctets(uint8_t a, uint8_t b, uint8_t c, uint8_t d)
    {
        return NetworkAddress((uint32_t{a} << 24) | (uint32_t{b} << 16) | (uint32_t{c} << 8) | d);
    }

    constexpr uint32_t raw() const { return raw_; }
    /// The net id: the first octet.
    constexpr uint8_t net() const { return static_cast<uint8_t>(raw_ >> 24); }

    constexpr Kind kind() const
    {
        const uint8_t first = net();
        if (raw_ == 0xFFFFFFFFu) {
            return Kind::LimitedBroadcast;
        }
        if (first >= 224 && first <= 239) {
            return Kind::Multicast;
        }
        if (first < 128 || first > 223) {
            return Kind::Invalid;
        }
        return (raw_ & 0x00FFFFFFu) == 0x00FFFFFFu ? Kind::DirectedBroadcast : Kind::Unicast;
    }

    constexpr bool isUnicast() const { return kind() == Kind::Unicast; }

    /// The mask of a prefix length from kMinimumPrefixLength to kMaximumPrefixLength.
    static constexpr uint32_t maskOf(uint8_t prefixLength)
    {
        return prefixLength >= 32 ? 0xFFFFFFFFu : ~(0xFFFFFFFFu >> prefixLength);
    }

    /// Whether this address lies in the subnet of @p subnet with @p prefixLength leading bits.
    constexpr bool isIn(NetworkAddress subnet, uint8_t prefixLength) const
    {
        return ((raw_ ^ subnet.raw_) & maskOf(prefixLength)) == 0;
    }

    /// Writes "a.b.c.d" and a terminator into @p text (at least kTextSize bytes).
    void format(char (&text)[kTextSize]) const;

    /// Reads "a.b.c.d" (four decimal octets, nothing else); false when @p text is not one.
    static bool parse(const char* text, NetworkAddress& address);

    friend constexpr bool operator==(NetworkAddress a, NetworkAddress b) { return a.raw_ == b.raw_; }

private:
    uint32_t raw_ = 0;
};

} // namespace dcos
