#include <image/EcdsaP256.hpp>

#include <mbedtls/ecdsa.h>

namespace image {

namespace {

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
    Curve curve;
    return curve.readPoint(publicKey);
}

} // namespace image
