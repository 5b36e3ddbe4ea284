#!/usr/bin/python3
"""An independent Modbus TCP peer for the modbus plugin's tests: Debian's python3-pymodbus (3.0)
serving known register contents on 127.0.0.1:<port>.

The contents are packed here with Python's struct module, not with any code of ours, so a test
that reads the right SI values proves the plugin's decoding against someone else's encoding.
Addresses are 0-based (zero_mode=True; without it pymodbus serves block[1] at address 0).

Input registers:
   0      int16    -1234
   1      uint16   50000
   2-3    int32    -100000      high word first
   4-5    int32    -100000      low word first
   6-7    float32  12.5         high word first
   8-9    float32  12.5         low word first
  10      int16    2500         (a scaled channel: 2500 * 0.01 - 5 = 20)
  11-12   float32  2.5e7        high word first
Holding registers: 0-19 zero (write targets), 20 uint16 777
Discrete inputs:   0 = 1, 1 = 0, 2 = 1
Coils:             all 0 (write targets)
Every table has 100 entries, so address 100 and above answer "illegal data address".

Usage: pymodbus_server.py <port>          Modbus TCP on 127.0.0.1:<port>
       pymodbus_server.py rtu <device>    Modbus RTU, 19200 8N1, on a serial device (a pty)
"""
import logging
import struct
import sys

from pymodbus.datastore import (ModbusSequentialDataBlock, ModbusServerContext,
                                ModbusSlaveContext)
from pymodbus.server import StartSerialServer, StartTcpServer
from pymodbus.transaction import ModbusRtuFramer

SIZE = 100


def words(fmt, value, high_first=True):
    """The registers of a 32-bit value, as a device with that word order lays them out."""
    high, low = struct.unpack(">HH", struct.pack(fmt, value))
    return [high, low] if high_first else [low, high]


def main():
    ir = [0] * SIZE
    ir[0] = struct.unpack(">H", struct.pack(">h", -1234))[0]
    ir[1] = 50000
    ir[2:4] = words(">i", -100000, True)
    ir[4:6] = words(">i", -100000, False)
    ir[6:8] = words(">f", 12.5, True)
    ir[8:10] = words(">f", 12.5, False)
    ir[10] = 2500
    ir[11:13] = words(">f", 2.5e7, True)
    hr = [0] * SIZE
    hr[20] = 777
    di = [0] * SIZE
    di[0], di[1], di[2] = 1, 0, 1
    co = [0] * SIZE

    store = ModbusSlaveContext(
        di=ModbusSequentialDataBlock(0, di),
        co=ModbusSequentialDataBlock(0, co),
        hr=ModbusSequentialDataBlock(0, hr),
        ir=ModbusSequentialDataBlock(0, ir),
        zero_mode=True,
    )
    # pymodbus logs every dropped connection and exception answer at ERROR: the tests provoke both.
    logging.getLogger("pymodbus").setLevel(logging.CRITICAL)
    context = ModbusServerContext(slaves=store, single=True)
    if sys.argv[1] == "rtu":
        StartSerialServer(context=context, framer=ModbusRtuFramer, port=sys.argv[2],
                          baudrate=19200, bytesize=8, parity="N", stopbits=1)
    else:
        # A restarted server must bind while the old connection sits in TIME_WAIT: pymodbus 3.0
        # leaves SO_REUSEADDR off by default.
        StartTcpServer(context=context, address=("127.0.0.1", int(sys.argv[1])), allow_reuse_address=True)


if __name__ == "__main__":
    main()
