#include <hostimage/SigningKey.hpp>

#include <hostimage/RandomGenerator.hpp>

#include <mbedtls/ecdsa.h>
#include <mbedtls/pk.h>

#include <fmt/core.h>

#include <vector>

namespace hostimage {

namespace {

// The key's curve must be P-256: the controllers verify nothing else.
bool onP256(mbedtls_pk_context& pk)
{
    return mbedtls_pk_get_type(&pk) == MBEDTLS_PK_ECKEY && mbedtls_pk_ec(pk)->grp.id == MBEDTLS_ECP_DP_SECP256R1;
}

bool writePoint(mbedtls_pk_context& pk, SigningKey::PublicPoint& point)
{
    mbedtls_ecp_keypair* key = mbedtls_pk_ec(pk);
    size_t length = 0;
    return mbedtls_ecp_point_write_binary(&key->grp, &key->Q, MBEDTLS_ECP_PF_UNCOMPRESSED, &length, point.data(),
                                          point.size()) == 0 &&
           length == point.size();
}

// mbedTLS parses PEM only with its terminating NUL counted in the length.
std::vector<unsigned char> pemBytes(const std::string& pem)
{
    return std::vector<unsigned char>(pem.c_str(), pem.c_str() + pem.size() + 1);
}

} // namespace

struct SigningKey::Context {
    mbedtls_pk_context pk;
    Context() { mbedtls_pk_init(&pk); }
    ~Context() { mbedtls_pk_free(&pk); }
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
};

SigningKey::SigningKey(std::shared_ptr<Context> context) : context_(std::move(context)) {}

std::optional<SigningKey> SigningKey::generate(std::string& error)
{
    RandomGenerator random("dcos-image");
    if (random.status() != 0) {
        error = describeMbedtlsError("cannot seed the random generator from the system's entropy", random.status());
        return std::nullopt;
    }
    auto context = std::make_shared<Context>();
    int status = mbedtls_pk_setup(&context->pk, mbedtls_pk_info_from_type(MBEDTLS_PK_ECKEY));
    if (status == 0) {
        status = mbedtls_ecp_gen_key(MBEDTLS_ECP_DP_SECP256R1, mbedtls_pk_ec(context->pk), mbedtls_ctr_drbg_random,
                                     random.drbg());
    }
    if (status != 0) {
        error = describeMbedtlsError("cannot generate a P-256 key", status);
        return std::nullopt;
    }
    SigningKey key(context);
    if (!writePoint(context->pk, key.point_)) {
        error = "cannot export the new key's public point";
        return std::nullopt;
    }
    return key;
}

std::optional<SigningKey> SigningKey::fromPem(const std::string& pem, std::string& error)
{
    auto context = std::make_shared<Context>();
    const std::vector<unsigned char> bytes = pemBytes(pem);
    const int status = mbedtls_pk_parse_key(&context->pk, bytes.data(), bytes.size(), nullptr, 0);
    if (status != 0) {
        error = describeMbedtlsError("not a private key in PEM", status);
        return std::nullopt;
    }
    if (!onP256(context->pk)) {
        error = "not an ECDSA P-256 (secp256r1) key";
        return std::nullopt;
    }
    SigningKey key(context);
    if (!writePoint(context->pk, key.point_)) {
        error = "cannot export the key's public point";
        return std::nullopt;
    }
    return key;
}

std::string SigningKey::privatePem() const
{
    unsigned char text[1024] = {};
    if (mbedtls_pk_write_key_pem(&context_->pk, text, sizeof text) != 0) {
        return {};
    }
    return reinterpret_cast<const char*>(text);
}

std::string SigningKey::publicPem() const
{
    unsigned char text[512] = {};
    if (mbedtls_pk_write_pubkey_pem(&context_->pk, text, sizeof text) != 0) {
        return {};
    }
    return reinterpret_cast<const char*>(text);
}

bool SigningKey::sign(const uint8_t (&digest)[32], uint8_t (&signature)[image::EcdsaP256::kSignatureSize],
                      std::string& error) const
{
    // The nonce comes from the key and the digest (RFC 6979); the random
    // generator only blinds the computation against side channels.
    RandomGenerator random("dcos-image");
    if (random.status() != 0) {
        error = describeMbedtlsError("cannot seed the random generator from the system's entropy", random.status());
        return false;
    }
    mbedtls_ecp_keypair* key = mbedtls_pk_ec(context_->pk);
    mbedtls_mpi r;
    mbedtls_mpi s;
    mbedtls_mpi_init(&r);
    mbedtls_mpi_init(&s);
    int status = mbedtls_ecdsa_sign_det_ext(&key->grp, &r, &s, &key->d, digest, sizeof digest, MBEDTLS_MD_SHA256,
                                            mbedtls_ctr_drbg_random, random.drbg());
    if (status == 0) {
        status = mbedtls_mpi_write_binary(&r, signature, 32);
    }
    if (status == 0) {
        status = mbedtls_mpi_write_binary(&s, signature + 32, 32);
    }
    mbedtls_mpi_free(&s);
    mbedtls_mpi_free(&r);
    if (status != 0) {
        error = describeMbedtlsError("cannot sign", status);
        return false;
    }
    return true;
}

std::optional<SigningKey::PublicPoint> SigningKey::publicPointFromPem(const std::string& pem, std::string& error)
{
    Context context;
    const std::vector<unsigned char> bytes = pemBytes(pem);
    int status = mbedtls_pk_parse_public_key(&context.pk, bytes.data(), bytes.size());
    if (status != 0) {
        mbedtls_pk_free(&context.pk);
        mbedtls_pk_init(&context.pk);
        status = mbedtls_pk_parse_key(&context.pk, bytes.data(), bytes.size(), nullptr, 0);
    }
    if (status != 0) {
        error = describeMbedtlsError("not a public or private key in PEM", status);
        return std::nullopt;
    }
    if (!onP256(context.pk)) {
        error = "not an ECDSA P-256 (secp256r1) key";
        return std::nullopt;
    }
    PublicPoint point{};
    if (!writePoint(context.pk, point)) {
        error = "cannot export the key's public point";
        return std::nullopt;
    }
    return point;
}

} // namespace hostimage
