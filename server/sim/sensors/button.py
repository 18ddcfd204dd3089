"""A push button read as std_msgs/Bool (the CrowBot's programmable button, 000 section 3.2,
Fig. 10). Pressed by a scripted event or, later, from the browser; no bounce is modelled because
the firmware publishes the debounced digitalRead level."""

from __future__ import annotations

import numpy as np

from sandbox.msgs.std_msgs import Bool
from server.sim.sensors.base import SenseContext, StatelessSensor


class Button(StatelessSensor):
    msg_type = Bool

    def __init__(self, rate_hz: float) -> None:
        self.rate_hz = rate_hz

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Bool:
        return Bool(data=ctx.state.button_pressed)
