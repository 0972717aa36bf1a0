#include <dcos/internal/SystemTick.hpp>

#include <arch_x86/Cpu.hpp>

namespace dcos {

volatile uint64_t SystemTick::count_ = 0;

uint64_t SystemTick::count()
{
    arch_x86::InterruptGuard guard;
    return count_;
}

} // namespace dcos
