/* mbedTLS's configuration for the firmware (mk/mbedtls.mk): what a
 * controller needs to check a signed image (docs/boot.md), and nothing
 * else. SHA-256 and ECDSA P-256 verification, on big numbers in a static
 * arena (memory_buffer_alloc): no heap of the kernel's, no entropy, no
 * file system, no clock, no standard library beyond the memory functions
 * firmware/runtime supplies. mbedTLS 2.28's option names (config.h). */
#ifndef DCOS_MBEDTLS_CONFIG_H
#define DCOS_MBEDTLS_CONFIG_H

/* The i386 multiply-accumulate in bn_mul.h: MOV, MUL, ADD and ADC, which
 * the i486 has; its SSE2 variant is not enabled. */
#define MBEDTLS_HAVE_ASM

/* A freestanding platform: calloc and free come from the static arena
 * set up by image::CryptoArena, and no time, entropy or printf exist. */
#define MBEDTLS_PLATFORM_C
#define MBEDTLS_PLATFORM_MEMORY
#define MBEDTLS_PLATFORM_NO_STD_FUNCTIONS
#define MBEDTLS_MEMORY_BUFFER_ALLOC_C
#define MBEDTLS_NO_PLATFORM_ENTROPY
/* memory_buffer_alloc stops the program when it finds its arena's
 * bookkeeping corrupted: that is a panic on the controller (EcdsaP256.cpp). */
#define MBEDTLS_PLATFORM_EXIT_MACRO dcos_mbedtls_exit
#ifdef __cplusplus
extern "C"
#endif
    void
    dcos_mbedtls_exit(int status);

#define MBEDTLS_BIGNUM_C
#define MBEDTLS_ECP_C
#define MBEDTLS_ECP_DP_SECP256R1_ENABLED
#define MBEDTLS_ECP_NIST_OPTIM
/* A small window and no precomputed table of the base point: verification
 * costs a little more, the arena far less (ecp.c's comments on both). */
#define MBEDTLS_ECP_WINDOW_SIZE 2
#define MBEDTLS_ECP_FIXED_POINT_OPTIM 0
/* ecp.c's internal random generator blinds a secret scalar when the
 * caller gives no generator. Verification has no secret, and the firmware
 * has no entropy to seed a generator with. */
#define MBEDTLS_ECP_NO_INTERNAL_RNG
#define MBEDTLS_ECDSA_C
/* ecdsa.c needs them for its DER functions, which the firmware never calls. */
#define MBEDTLS_ASN1_PARSE_C
#define MBEDTLS_ASN1_WRITE_C

#define MBEDTLS_SHA256_C
/* Not MBEDTLS_SHA256_SMALLER: the unrolled rounds hash a KiB in 12 % fewer
 * instructions for some 2.5 KiB more code (make bench, Image.Sha256KiB),
 * and a boot hashes the whole image. */

#include "mbedtls/check_config.h"

#endif
