// mbedTLS's CTR-DRBG seeded from the system's entropy, freed on every path:
// the one source of random bytes of the host tools (signing nonces, new
// signing and configuration keys).
#pragma once

#include <mbedtls/ctr_drbg.h>
#include <mbedtls/entropy.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace hostimage {

class RandomGenerator {
public:
    /// Seeds the generator; status() says whether that worked.
    explicit RandomGenerator(const char* personalisation);
    ~RandomGenerator();
    RandomGenerator(const RandomGenerator&) = delete;
    RandomGenerator& operator=(const RandomGenerator&) = delete;

    /// 0 when seeded, else mbedTLS's error code.
    int status() const { return status_; }
    /// For the mbedTLS calls that take a generator (with mbedtls_ctr_drbg_random).
    mbedtls_ctr_drbg_context* drbg() { return &drbg_; }
    /// Fills @p size bytes at @p out; 0 or mbedTLS's error code.
    int fill(uint8_t* out, size_t size) { return mbedtls_ctr_drbg_random(&drbg_, out, size); }

private:
    mbedtls_entropy_context entropy_;
    mbedtls_ctr_drbg_context drbg_;
    int status_;
};

/// "what: mbedTLS's text (mbedTLS -0xNNNN)".
std::string describeMbedtlsError(const char* what, int code);

} // namespace hostimage
