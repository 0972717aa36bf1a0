#include <hostmodbus/Simulator.hpp>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hostmodbus {

namespace {

// The register a computed value lands in: rounded, and held at the ends of
// the unsigned 16-bit range rather than wrapped (a sine around 0 is cut at
// 0, not turned into 65535).
uint16_t toRegister(double value)
{
    return static_cast<uint16_t>(std::clamp(std::lround(value), 0L, 65535L));
}

struct Span {
    unsigned start = 0;
    unsigned count = 0;
};

Span spanOf(const SimulatorConfig& config, Table table)
{
    unsigned low = 0x10000;
    unsigned high = 0;
    for (const Point& p : config.points) {
        if (p.table == table) {
            low = std::min<unsigned>(low, p.address);
            high = std::max<unsigned>(high, p.address + p.count);
        }
    }
    return low < high ? Span{low, high - low} : Span{};
}

} // namespace

Simulator::Simulator(const SimulatorConfig& config, uint32_t seed)
    : config_(config), random_(seed), rampPosition_(config.points.size(), 0.0)
{
}

Simulator::~Simulator()
{
    if (mapping_ != nullptr) {
        modbus_mapping_free(mapping_);
    }
}

Result<std::unique_ptr<Simulator>> Simulator::create(const SimulatorConfig& config, uint32_t seed)
{
    using R = Result<std::unique_ptr<Simulator>>;
    std::unique_ptr<Simulator> simulator(new Simulator(config, seed));
    const Span coils = spanOf(config, Table::Coil);
    const Span inputs = spanOf(config, Table::DiscreteInput);
    const Span holding = spanOf(config, Table::HoldingRegister);
    const Span input = spanOf(config, Table::InputRegister);
    simulator->mapping_ = modbus_mapping_new_start_address(coils.start, coils.count, inputs.start, inputs.count,
                                                           holding.start, holding.count, input.start, input.count);
    if (simulator->mapping_ == nullptr) {
        return R::failure(fmt::format("the register map could not be allocated: {}", modbus_strerror(errno)));
    }
    for (size_t i = 0; i < config.points.size(); ++i) {
        const Point& p = config.points[i];
        for (unsigned k = 0; k < p.count; ++k) {
            const auto address = static_cast<uint16_t>(p.address + k);
            if (isRegisterTable(p.table)) {
                *simulator->registerAt(p.table, address) = p.value;
            } else {
                *simulator->bitAt(p.table, address) = static_cast<uint8_t>(p.value);
            }
        }
        simulator->rampPosition_[i] = p.value;
    }
    simulator->advance(0);
    return R::success(std::move(simulator));
}

uint16_t* Simulator::registerAt(Table table, uint16_t address) const
{
    if (table == Table::HoldingRegister) {
        return &mapping_->tab_registers[address - mapping_->start_registers];
    }
    return &mapping_->tab_input_registers[address - mapping_->start_input_registers];
}

uint8_t* Simulator::bitAt(Table table, uint16_t address) const
{
    if (table == Table::Coil) {
        return &mapping_->tab_bits[address - mapping_->start_bits];
    }
    return &mapping_->tab_input_bits[address - mapping_->start_input_bits];
}

uint16_t Simulator::value(size_t index) const
{
    const Point& p = config_.points[index];
    return isRegisterTable(p.table) ? *registerAt(p.table, p.address) : *bitAt(p.table, p.address);
}

void Simulator::write(size_t index, uint16_t value)
{
    const Point& p = config_.points[index];
    if (isRegisterTable(p.table)) {
        *registerAt(p.table, p.address) = value;
    } else {
        *bitAt(p.table, p.address) = value != 0 ? 1 : 0;
    }
}

double Simulator::noise(double amplitude)
{
    if (amplitude <= 0) {
        return 0;
    }
    std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
    return uniform(random_);
}

void Simulator::advance(double seconds)
{
    elapsed_ += seconds;
    // Registers first, bits second: a comparison sees the values this step
    // produced, so "at speed" turns on in the same step the ramp arrives.
    for (const bool registers : {true, false}) {
        for (size_t i = 0; i < config_.points.size(); ++i) {
            const Point& p = config_.points[i];
            const Behaviour& b = p.behaviour;
            if (isRegisterTable(p.table) != registers || b.kind == Behaviour::Kind::None) {
                continue;
            }
            switch (b.kind) {
            case Behaviour::Kind::Ramp: {
                const bool enabled = b.enable < 0 || value(static_cast<size_t>(b.enable)) != 0;
                const double target = enabled ? value(static_cast<size_t>(b.source)) : 0.0;
                double& position = rampPosition_[i];
                const double step = b.perSecond * seconds;
                position = position < target ? std::min(target, position + step) : std::max(target, position - step);
                write(i, toRegister(position));
                break;
            }
            case Behaviour::Kind::Sine:
                write(i, toRegister(b.offset +
                                    b.amplitude * std::sin(2 * std::numbers::pi * elapsed_ / b.periodSeconds) +
                                    noise(b.noise)));
                break;
            case Behaviour::Kind::Constant:
                write(i, toRegister(b.offset + noise(b.noise)));
                break;
            case Behaviour::Kind::Compare: {
                const double a = value(static_cast<size_t>(b.source));
                const double other = value(static_cast<size_t>(b.other));
                write(i, std::fabs(a - other) <= b.tolerance ? 1 : 0);
                break;
            }
            case Behaviour::Kind::None:
                break;
            }
        }
    }
}

bool Simulator::declared(Table table, uint32_t address, uint32_t count) const
{
    // Walks the range entry by entry; a range is at most 2000 items and the
    // map a few dozen entries, so no index is needed.
    uint32_t next = address;
    const uint32_t end = address + count;
    bool moved = true;
    while (next < end && moved) {
        moved = false;
        for (const Point& p : config_.points) {
            if (p.table == table && p.address <= next && next < static_cast<uint32_t>(p.address) + p.count) {
                next = static_cast<uint32_t>(p.address) + p.count;
                moved = true;
            }
        }
    }
    return next >= end;
}

} // namespace hostmodbus
