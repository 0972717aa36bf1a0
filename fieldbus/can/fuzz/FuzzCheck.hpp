// The fuzz targets' assertion: a broken invariant is a crash libFuzzer
// records, with the condition and line printed first.
#pragma once

#include <cstddef>
#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(condition)                                                                            \
    do {                                                                                                 \
        if (!(condition)) {                                                                              \
            std::fprintf(stderr, "%s:%d: invariant broken: %s\n", __FILE__, __LINE__, #condition);       \
            std::abort();                                                                                \
        }                                                                                                \
    } while (false)

namespace fuzz {

// Reads the fuzzer's input front to back; past the end it yields zeros, so a
// target never reads outside the input and every input is a valid program.
class InputReader {
public:
    InputReader(const unsigned char* data, std::size_t size) : data_(data), size_(size) {}

    bool empty() const { return position_ >= size_; }

    unsigned char byte() { return position_ < size_ ? data_[position_++] : 0; }

    unsigned long bytes(int count)
    {
        unsigned long value = 0;
        for (int i = 0; i < count; ++i) {
            value = (value << 8) | byte();
        }
        return value;
    }

private:
    const unsigned char* data_;
    std::size_t size_;
    std::size_t position_ = 0;
};

} // namespace fuzz
