"""What the link talks through: a serial port on the wall clock, or any object with the same four
calls (the simulation's in-process line runs on its simulated clock, host.emulator.lockstep)."""

from __future__ import annotations

import time
from typing import Protocol

import serial


class PortError(Exception):
    """The port failed; the message is one line (the link names the port)."""


class Port(Protocol):
    """A byte line to the robot and the clock its waits are measured on."""

    def now(self) -> float:
        """Seconds on the clock that reply and retry timeouts use."""
        ...

    def write(self, data: bytes) -> None:
        """Send data; raises PortError when the line is gone."""
        ...

    def read(self, wait_s: float) -> bytes:
        """The bytes arrived, waiting up to about wait_s for the first (b"" when none came)."""
        ...

    def close(self) -> None: ...


class SerialPort:
    """A device path or pyserial URL. A write that times out (a starved host, a full pty) is
    tried again for write_patience_s before the port counts as lost."""

    def __init__(self, url: str, baud: int, write_timeout_s: float = 1.0,
                 write_patience_s: float = 5.0) -> None:
        self.write_patience_s = write_patience_s
        self.write_timeouts = 0  # writes that timed out and were tried again
        try:
            self._ser = serial.serial_for_url(url, baudrate=baud, timeout=0.005,
                                              write_timeout=write_timeout_s)
        except (serial.SerialException, OSError, ValueError) as e:
            raise PortError(reason(e)) from None

    def now(self) -> float:
        return time.monotonic()

    def write(self, data: bytes) -> None:
        give_up = time.monotonic() + self.write_patience_s
        while True:
            try:
                self._ser.write(data)
                return
            except serial.SerialTimeoutException:
                # pyserial does not say how much went out before the timeout: the whole frame
                # goes again (the robot's parser drops a cut-off frame by its CRC)
                self.write_timeouts += 1
                if time.monotonic() >= give_up:
                    raise PortError(f"write timeout: nothing could be written for "
                                    f"{self.write_patience_s:g} s") from None
            except (serial.SerialException, OSError) as e:
                raise PortError(reason(e)) from None

    def read(self, wait_s: float) -> bytes:
        try:
            data: bytes = self._ser.read(max(1, self._ser.in_waiting))  # waits up to its 5 ms
            return data  # timeout
        except (serial.SerialException, OSError) as e:
            raise PortError(reason(e)) from None

    def close(self) -> None:
        self._ser.close()


def reason(e: BaseException) -> str:
    """One line for an exception from pyserial or the OS."""
    text = str(e).strip() or type(e).__name__
    if "No such file" in text or "could not open port" in text and "[Errno 2]" in text:
        return "no such device"
    if "Permission denied" in text or "[Errno 13]" in text:
        return "permission denied (add yourself to the dialout group)"
    return text.splitlines()[0]
