// A CharacterSink that collects output into a std::string, for host tests.
#pragma once

#include <runtime/Format.hpp>

#include <string>

class StringSink final : public runtime::CharacterSink {
public:
    void put(char character) override { text += character; }
    std::string take()
    {
        std::string out;
        out.swap(text);
        return out;
    }
    std::string text;
};
