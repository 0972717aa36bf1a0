#!/usr/bin/env python3
"""A pymodbus RTU slave on a serial port, for dcos-modbus's interoperability tests.

pymodbus (Debian's python3-pymodbus) is an implementation of Modbus we did
not write: dcos-modbus must read and write it with every function code it
offers. The slave holds known values (the table below, which the tests
compare with), answers as slave --slave, and prints "ready" once its port
is open. It runs until killed, or for --seconds at most, so a test that
dies never leaves it behind for long.

Every table starts at address 0 and has 100 items (zero_mode: address a is
item a, not a+1 as pymodbus counts by default); anything past 99 is answered
with exception 02, illegal data address.
"""

import argparse
import asyncio
import logging
import sys

from pymodbus.datastore import ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext
from pymodbus.device import ModbusDeviceIdentification
from pymodbus.server import StartAsyncSerialServer
from pymodbus.transaction import ModbusRtuFramer

SIZE = 100
COILS = [i % 3 == 0 for i in range(SIZE)]
DISCRETE_INPUTS = [i % 2 == 1 for i in range(SIZE)]
HOLDING_REGISTERS = [1000 + i for i in range(SIZE)]
INPUT_REGISTERS = [(i * 257) & 0xFFFF for i in range(SIZE)]
IDENTITY = {
    "VendorName": "pymodbus",
    "ProductCode": "PM-SLAVE",
    "MajorMinorRevision": "3.0.0",
    "VendorUrl": "https://github.com/pymodbus-dev/pymodbus",
    "ProductName": "pymodbus test slave",
    "ModelName": "interop",
}


async def serve(arguments):
    store = ModbusSlaveContext(
        co=ModbusSequentialDataBlock(0, list(COILS)),
        di=ModbusSequentialDataBlock(0, list(DISCRETE_INPUTS)),
        hr=ModbusSequentialDataBlock(0, list(HOLDING_REGISTERS)),
        ir=ModbusSequentialDataBlock(0, list(INPUT_REGISTERS)),
        zero_mode=True,
    )
    context = ModbusServerContext(slaves={arguments.slave: store}, single=False)
    identity = ModbusDeviceIdentification(info_name=IDENTITY)
    server = await StartAsyncSerialServer(
        context=context, identity=identity, port=arguments.port, framer=ModbusRtuFramer,
        baudrate=arguments.baud, parity=arguments.parity, stopbits=1, bytesize=8,
        ignore_missing_slaves=True, defer_start=True)
    await server.start()
    if server.transport is None:
        print(f"pymodbus_slave: cannot open {arguments.port}", file=sys.stderr, flush=True)
        sys.exit(3)
    print("ready", flush=True)
    await asyncio.sleep(arguments.seconds)
    await server.shutdown()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("port")
    parser.add_argument("--slave", type=int, default=17)
    parser.add_argument("--baud", type=int, default=19200)
    parser.add_argument("--parity", default="E")
    parser.add_argument("--seconds", type=float, default=120)
    arguments = parser.parse_args()
    logging.basicConfig(level=logging.WARNING, stream=sys.stderr)
    asyncio.run(serve(arguments))


if __name__ == "__main__":
    main()
