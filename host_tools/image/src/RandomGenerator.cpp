#include <hostimage/RandomGenerator.hpp>

#include <mbedtls/error.h>

#include <fmt/core.h>

#include <cstring>

namespace hostimage {

RandomGenerator::RandomGenerator(const char* personalisation)
{
    mbedtls_entropy_init(&entropy_);
    mbedtls_ctr_drbg_init(&drbg_);
    status_ = mbedtls_ctr_drbg_seed(&drbg_, mbedtls_entropy_func, &entropy_,
                                    reinterpret_cast<const unsigned char*>(personalisation),
                                    std::strlen(personalisation));
}

RandomGenerator::~RandomGenerator()
{
    mbedtls_ctr_drbg_free(&drbg_);
    mbedtls_entropy_free(&entropy_);
}

std::string describeMbedtlsError(const char* what, int code)
{
    char text[128];
    mbedtls_strerror(code, text, sizeof text);
    return fmt::format("{}: {} (mbedTLS -0x{:04X})", what, text, static_cast<unsigned>(-code));
}

} // namespace hostimage
