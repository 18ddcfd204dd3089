"""Opening the Create's serial port, and the errors the driver raises, each a sentence that
says what to do."""

from __future__ import annotations

import errno

import serial

READ_TIMEOUT_S = 0.02  # [s] the reader wakes this often to check silence and the latch
WRITE_TIMEOUT_S = 1.0  # [s] a write that blocks this long means the adapter is gone


class CreateError(Exception):
    """Something about the robot or its port; the message says what to do."""


class CreatePortError(CreateError):
    """The serial port cannot be opened (missing, no permission, in use)."""


class CreateNoAnswerError(CreateError):
    """The port opened but no sensor stream came back."""


class CreateStateError(CreateError):
    """A call the driver's current state does not allow."""


def open_serial(port: str, baud: int) -> serial.Serial:
    """pyserial's port, its input flushed (a stream left running by an earlier session is
    not this one's), or a CreatePortError that says why not and what to do."""
    try:
        opened = serial.Serial(
            port,
            baudrate=baud,
            timeout=READ_TIMEOUT_S,
            write_timeout=WRITE_TIMEOUT_S,
            exclusive=True,  # two drivers on one robot would fight over its wheels
        )
    except ValueError as exc:
        raise CreatePortError(f"cannot open {port} at {baud} baud: {exc}") from exc
    except serial.SerialException as exc:
        code = getattr(exc, "errno", None)
        if code == errno.ENOENT:
            hint = (
                "there is no such device: is the USB-serial cable plugged in? "
                "`ls /dev/ttyUSB* /dev/ttyACM*` lists the ports there are"
            )
        elif code in (errno.EACCES, errno.EPERM):
            hint = (
                "permission denied: add the server's user to the port's group "
                "(`sudo usermod -aG dialout $USER`, then log in again)"
            )
        elif code in (errno.EBUSY, errno.EAGAIN, errno.EWOULDBLOCK):
            hint = "another program holds the port: close it (`fuser` names it) and retry"
        else:
            hint = str(exc)
        raise CreatePortError(f"cannot open the Create's serial port {port}: {hint}") from exc
    try:
        opened.reset_input_buffer()
    except (serial.SerialException, OSError) as exc:
        opened.close()
        raise CreatePortError(f"cannot use the Create's serial port {port}: {exc}") from exc
    return opened
