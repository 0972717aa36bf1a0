// The host build's stand-in for the MMU: it records which pages portable
// code made not present, so tests can check the guards it sets and clears.
#include <arch_x86/Paging.hpp>

#include <set>

namespace {

std::set<uintptr_t>& absentPages()
{
    static std::set<uintptr_t> pages;
    return pages;
}

} // namespace

namespace arch_x86 {

void Paging::setPresent(uintptr_t page, bool present)
{
    if (present) {
        absentPages().erase(pageBase(page));
    } else {
        absentPages().insert(pageBase(page));
    }
}

bool Paging::isPresent(uintptr_t address) { return absentPages().count(pageBase(address)) == 0; }

} // namespace arch_x86
