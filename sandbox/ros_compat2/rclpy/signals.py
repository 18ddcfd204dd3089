"""rclpy.signals: accepted for compatibility. A RoboDojo node gets no signals: the run ends
it with a Shutdown frame, which shuts its contexts down as rclpy's SIGINT handler would."""

from __future__ import annotations

from enum import IntEnum


class SignalHandlerOptions(IntEnum):
    NO = 0
    SIGINT = 1
    SIGTERM = 2
    ALL = 3


def install_signal_handlers(options: SignalHandlerOptions = SignalHandlerOptions.ALL) -> None:
    pass


def get_current_signal_handlers_options() -> SignalHandlerOptions:
    return SignalHandlerOptions.ALL


def uninstall_signal_handlers() -> None:
    pass
