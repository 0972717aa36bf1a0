#include <image/EcdsaP256.hpp>

#include <mbedtls/ecdsa.h>
#if defined(MBEDTLS_MEMORY_BUFFER_ALLOC_C)
#include <mbedtls/memory_buffer_alloc.h>

#include <boot/Panic.hpp>

// The arena's bookkeeping was found corrupted: memory the verifier owns was
// written by someone else, which no error code can undo.
extern "C" void dcos_mbedtls_exit(int status)
{
    dcosPanic("mbedTLS found its memory arena corrupted (status %d)", status);
}
#endif

namespace image {

namespace {

#if defined(MBEDTLS_MEMORY_BUFFER_ALLOC_C)
// On the controller (mk/mbedtls.mk), mbedTLS computes in a static arena:
// there is no heap to take from, and a verification must not fail for lack
// of memory the kernel's tasks use. 8 KiB holds a P-256 verification with
// the configuration's window of 2 several times over (the on-target test
// "image" verifies real signatures in it). Not reentrant: a second
// verification while one runs (another task) is refused, never allowed to
// share the arena.
constexpr size_t kArenaSize = 8192;
alignas(8) unsigned char arena[kArenaSize];
bool arenaReady = false;
int busy = 0;

class ArenaUse {
public:
    ArenaUse() : owned_(__atomic_exchange_n(&busy, 1, __ATOMIC_ACQUIRE) == 0)
    {
        if (owned_ && !arenaReady) {
            mbedtls_memory_buffer_alloc_init(arena, sizeof arena);
            arenaReady = true;
        }
    }
    ~ArenaUse()
    {
        if (owned_) {
            __atomic_store_n(&busy, 0, __ATOMIC_RELEASE);
        }
    }
    ArenaUse(const ArenaUse&) = delete;
    ArenaUse& operator=(const ArenaUse&) = delete;

    bool owned() const { return owned_; }

private:
    bool owned_;
};
#else
// On the host, Debian's mbedTLS takes its memory from the C library.
class ArenaUse {
public:
    bool owned() const { return true; }
};
#endif

// The curve and a point read into mbedTLS's types, freed on every path.
class Curve {
public:
    Curve()
    {
        mbedtls_ecp_group_init(&group_);
        mbedtls_ecp_point_init(&point_);
        loaded_ = mbedtls_ecp_group_load(&group_, MBEDTLS_ECP_DP_SECP256R1) == 0;
    }
    ~Curve()
    {
        mbedtls_ecp_point_free(&point_);
        mbedtls_ecp_group_free(&group_);
    }
    Curve(const Curve&) = delete;
    Curve& operator=(const Curve&) = delete;

    // Reads the point and checks that it lies on the curve.
    bool readPoint(const uint8_t (&publicKey)[EcdsaP256::kPublicKeySize])
    {
        return loaded_ && publicKey[0] == 0x04 &&
               mbedtls_ecp_point_read_binary(&group_, &point_, publicKey, sizeof publicKey) == 0 &&
               mbedtls_ecp_check_pubkey(&group_, &point_) == 0;
    }

    mbedtls_ecp_group& group() { return group_; }
    mbedtls_ecp_point& point() { return point_; }

private:
    mbedtls_ecp_group group_;
    mbedtls_ecp_point point_;
    bool loaded_ = false;
};

class Scalar {
public:
    explicit Scalar(const uint8_t* bytes) : read_(false)
    {
        mbedtls_mpi_init(&value_);
        read_ = mbedtls_mpi_read_binary(&value_, bytes, 32) == 0;
    }
    ~Scalar() { mbedtls_mpi_free(&value_); }
    Scalar(const Scalar&) = delete;
    Scalar& operator=(const Scalar&) = delete;

    bool read() const { return read_; }
    const mbedtls_mpi& value() const { return value_; }

private:
    mbedtls_mpi value_;
    bool read_;
};

} // namespace

bool EcdsaP256::verify(const uint8_t (&publicKey)[kPublicKeySize], const uint8_t (&digest)[kDigestSize],
                       const uint8_t (&signature)[kSignatureSize])
{
    const ArenaUse arena;
    if (!arena.owned()) {
        return false;
    }
    Curve curve;
    if (!curve.readPoint(publicKey)) {
        return false;
    }
    const Scalar r(signature);
    const Scalar s(signature + 32);
    // mbedtls_ecdsa_verify refuses r and s outside [1, n - 1] itself.
    return r.read() && s.read() &&
           mbedtls_ecdsa_verify(&curve.group(), digest, sizeof digest, &curve.point(), &r.value(), &s.value()) == 0;
}

bool EcdsaP256::validPublicKey(const uint8_t (&publicKey)[kPublicKeySize])
{
    const ArenaUse arena;
    if (!arena.owned()) {
        return false;
    }
    Curve curve;
    return curve.readPoint(publicKey);
}

} // namespace image
