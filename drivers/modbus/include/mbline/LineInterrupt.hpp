// The RS-485 line's work in the UART's receive interrupt, declared here so
// that the bench image (tests_renode/bench/ModbusBench.cpp) measures the
// very function the line's task gives its port rather than a copy of it.
// Defined with the board's lines in BoardLine.cpp (target only: it reads
// the timer agent's clock).
#pragma once

#include <stdint.h>

namespace mbline {

/// The receive sink the line gives the RS-485 port's 16550
/// (bsp::Uart16550::setReceiveSink), called in its interrupt for every byte
/// taken from the FIFO: stamps @p byte with the uptime (the end of its stop
/// bit, within the interrupt's latency) and queues it, with whether the UART
/// flagged it @p damaged, for @p runner, a LineRunner*, whose task feeds it
/// to the RTU receiver.
void stampReceivedByte(void* runner, uint8_t byte, bool damaged);

} // namespace mbline
