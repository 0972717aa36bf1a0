#include <image/Sha256.hpp>

namespace image {

// mbedTLS 2.28's SHA-256 fails only on a bad context or a hardware
// accelerator's fault; there is neither here, so the results are not
// checked, and a failure would show as a digest that matches nothing.
Sha256::Sha256()
{
    mbedtls_sha256_init(&context_);
    (void)mbedtls_sha256_starts_ret(&context_, 0);
}

Sha256::~Sha256() { mbedtls_sha256_free(&context_); }

void Sha256::update(const uint8_t* data, size_t length)
{
    if (length != 0) {
        (void)mbedtls_sha256_update_ret(&context_, data, length);
    }
}

void Sha256::finish(uint8_t (&digest)[kDigestSize]) { (void)mbedtls_sha256_finish_ret(&context_, digest); }

void Sha256::digest(const uint8_t* data, size_t length, uint8_t (&out)[kDigestSize])
{
    Sha256 hash;
    hash.update(data, length);
    hash.finish(out);
}

} // namespace image
